"""The example scripts of examples/python run and draw their figures (docs/python.md)."""

import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR


@pytest.mark.parametrize("script", ["diagnose_hidden_effect.py", "plan_round.py"])
def test_example_draws_its_figure(script, tmp_path):
    figure = tmp_path / (script[:-3] + ".png")
    extra = [str(tmp_path)] if script == "plan_round.py" else []
    r = subprocess.run([sys.executable, str(SOURCE_DIR / "examples" / "python" / script), str(figure), *extra],
                       capture_output=True, text=True, env=dict(os.environ))
    assert r.returncode == 0, r.stderr
    assert figure.stat().st_size > 10_000
