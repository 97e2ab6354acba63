"""GPML (Rasmussen & Nickisch) under GNU Octave as the peer of gpilqg's FITC (case c of
bench/peers/compare_peers.py): gp(hyp, inf, [], cov, @likGauss, X, y) for the NLML and its gradient
with respect to the hyperparameters and the pseudo-inputs, timed inside Octave (tic / toc).

GPML is not packaged in Debian: point the environment variable GPML_PATH at an unpacked GPML
(the folder with gp.m and startup.m). Without it, or without `octave-cli` / `octave` on PATH, or when
Octave fails, the case is skipped with the reason; a missing peer never fails the comparison.

GPML 4.x: cov = {@apxSparse, {@covSEard}, xu} with infGaussLik and opt.s = 1 (FITC); GPML 3.x:
{@covFITC, {@covSEard}, xu} with infFITC. Both add snu2 = 1e-6 sf^2 to Kuu, gpilqg's default rule.
hyp.cov = [log l; log sf], hyp.lik = log sn, hyp.xu = Xu (M x D): gpilqg's theta in the same order, so
the gradient [dnlZ.cov; dnlZ.lik; dnlZ.xu(:)] compares entry by entry.
"""

import os
import shutil
import subprocess
import tempfile

import numpy as np

_SCRIPT = r"""
addpath('{gpml}'); startup;
X = load('X.txt'); y = load('y.txt'); hv = load('theta.txt'); xu = load('xu.txt');
D = size(X, 2);
hyp = struct('cov', hv(1:D+1)(:), 'lik', hv(D+2), 'xu', xu);
if exist('apxSparse', 'file')
  cov = {{@apxSparse, {{@covSEard}}, xu}};
  inf = @(varargin) infGaussLik(varargin{{:}}, struct('s', 1.0));
else
  cov = {{@covFITC, {{@covSEard}}, xu}};
  inf = @infFITC;
end
[nlZ, dnlZ] = gp(hyp, inf, [], cov, @likGauss, X, y);
t = zeros(1, {repeats});
for r = 1:{repeats}
  tic; [nlZ, dnlZ] = gp(hyp, inf, [], cov, @likGauss, X, y); t(r) = toc;
end
g = [dnlZ.cov(:); dnlZ.lik(:)];
if isfield(dnlZ, 'xu'), g = [g; dnlZ.xu(:)]; end
printf('peer_nlml %.17g\n', nlZ);
printf('peer_gradient'); printf(' %.17g', g); printf('\n');
printf('peer_seconds'); printf(' %.17g', t); printf('\n');
printf('peer_version Octave %s\n', OCTAVE_VERSION);
"""


def fitc_case(X, y, theta, inducing, repeats, timeout=3600):
    """The FITC NLML and gradient by GPML, or {"skipped": reason}."""
    gpml = os.environ.get("GPML_PATH")
    if not gpml:
        return {"skipped": "GPML_PATH is not set (GPML is not packaged in Debian; unpack it and set GPML_PATH)"}
    if not os.path.isfile(os.path.join(gpml, "gp.m")):
        return {"skipped": "GPML_PATH=%s has no gp.m" % gpml}
    octave = shutil.which("octave-cli") or shutil.which("octave")
    if octave is None:
        return {"skipped": "no octave-cli or octave on PATH (Debian package octave)"}
    d = X.shape[1]
    with tempfile.TemporaryDirectory(prefix="gpilqg_gpml_") as work:
        np.savetxt(os.path.join(work, "X.txt"), X, fmt="%.17g")
        np.savetxt(os.path.join(work, "y.txt"), y, fmt="%.17g")
        np.savetxt(os.path.join(work, "theta.txt"), theta[:d + 2][None, :], fmt="%.17g")
        np.savetxt(os.path.join(work, "xu.txt"), np.asarray(theta[d + 2:]).reshape((inducing, d), order="F"),
                   fmt="%.17g")
        with open(os.path.join(work, "fitc_case.m"), "w") as f:
            f.write(_SCRIPT.format(gpml=gpml.replace("'", "''"), repeats=repeats))
        try:
            run = subprocess.run([octave, "--no-gui", "--quiet", "--no-init-file", "fitc_case.m"], cwd=work,
                                 capture_output=True, text=True, timeout=timeout)
        except (OSError, subprocess.TimeoutExpired) as e:
            return {"skipped": "Octave did not finish: %s" % e}
    lines = {line.split(" ", 1)[0]: line.split(" ", 1)[1] for line in run.stdout.splitlines()
             if line.startswith("peer_") and " " in line}
    if run.returncode != 0 or not {"peer_nlml", "peer_gradient", "peer_seconds"} <= lines.keys():
        tail = (run.stderr or run.stdout).strip().splitlines()[-5:]
        return {"skipped": "Octave/GPML failed (exit %d): %s" % (run.returncode, " | ".join(tail))}
    seconds = [float(s) for s in lines["peer_seconds"].split()]
    return {"best_s": min(seconds), "median_s": float(np.median(seconds)), "times_s": seconds,
            "nlml": float(lines["peer_nlml"]), "gradient": [float(g) for g in lines["peer_gradient"].split()],
            "version": lines.get("peer_version", "")}
