"""The data sets and hyperparameters of bench/peers/compare_peers.py, and the HDF5 file that hands them
to gpilqg_peer_cases (layout in bench/peers/peer_input.hpp). Both sides read the same float64 arrays.

Data: a smooth function of D = 5 inputs uniform on [-2, 2]^5, the one of bench/gp_bench.cpp,
    y = sin(x1) cos(x2 / 2) + 0.3 x3 + 0.1 x4 x5 + N(0, 0.05^2),
with a fixed NumPy seed. The hyperparameters are gp_bench.cpp's typical_parameters(): gpilqg's
theta = [log l_1..log l_5, log sf, log sn] = [0.3, 0.5, 1.0, 0.8, 0.8, 0, log 0.05]. The FITC case
uses the same hyperparameters on its own data set, with M pseudo-inputs drawn from its inputs.
"""

import math

import h5py
import numpy as np

INPUTS = 5
THETA = np.array([0.3, 0.5, 1.0, 0.8, 0.8, 0.0, math.log(0.05)])

# Sizes of the cases and of the smoke test (--quick).
FULL = {"nlml_sizes": [1000, 4000], "fit_size": 1000, "fit_sizes": [1000, 4000], "predict_size": 4000,
        "test_points": 1750, "fitc_size": 5000, "fitc_inducing": 100}
QUICK = {"nlml_sizes": [300, 600], "fit_size": 300, "fit_sizes": [300, 600], "predict_size": 600, "test_points": 350,
         "fitc_size": 1000, "fitc_inducing": 20}


def synthetic(rng, n):
    """n points of the benchmark function: X (n, 5), y (n,)."""
    X = rng.uniform(-2.0, 2.0, size=(n, INPUTS))
    y = (np.sin(X[:, 0]) * np.cos(0.5 * X[:, 1]) + 0.3 * X[:, 2] + 0.1 * X[:, 3] * X[:, 4]
         + rng.normal(0.0, 0.05, size=n))
    return X, y


def make_cases(sizes, seed=17):
    """Every array of one run: the exact-GP set (large enough for every exact case, which use its
    first rows), its test points, and the FITC set with theta = [THETA; vec(Xu)] (Xu column-major,
    FitcLayout in gp/include/gpilqg/gp/fitc.hpp)."""
    rng = np.random.default_rng(seed)
    rows = max(max(sizes["nlml_sizes"]), sizes["fit_size"], max(sizes["fit_sizes"]), sizes["predict_size"])
    X, y = synthetic(rng, rows)
    X_test = rng.uniform(-2.0, 2.0, size=(sizes["test_points"], INPUTS))
    Xf, yf = synthetic(rng, sizes["fitc_size"])
    Xu = Xf[rng.choice(sizes["fitc_size"], size=sizes["fitc_inducing"], replace=False)]
    return {"X": X, "y": y, "theta": THETA.copy(), "X_test": X_test,
            "fitc_X": Xf, "fitc_y": yf, "fitc_theta": np.concatenate([THETA, Xu.ravel(order="F")]),
            "fitc_inducing": sizes["fitc_inducing"], "nlml_sizes": list(sizes["nlml_sizes"]),
            "fit_size": sizes["fit_size"], "fit_sizes": list(sizes["fit_sizes"]), "predict_size": sizes["predict_size"]}


def write_cases(path, cases):
    """The HDF5 file gpilqg_peer_cases reads (bench/peers/peer_input.hpp)."""
    with h5py.File(path, "w") as f:
        f["exact/X"] = cases["X"]
        f["exact/y"] = cases["y"]
        f["exact/theta"] = cases["theta"]
        f["exact/X_test"] = cases["X_test"]
        f["fitc/X"] = cases["fitc_X"]
        f["fitc/y"] = cases["fitc_y"]
        f["fitc/theta"] = cases["fitc_theta"]
        f.attrs["nlml_sizes"] = np.array(cases["nlml_sizes"], dtype=np.int64)
        f.attrs["fit_size"] = cases["fit_size"]
        f.attrs["fit_sizes"] = np.array(cases["fit_sizes"], dtype=np.int64)
        f.attrs["predict_size"] = cases["predict_size"]
