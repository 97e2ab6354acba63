#!/usr/bin/python3
"""A held-out regression set of the shape `gpilqg profile` must handle within its time budget
(docs/results/performance.md): 8,752 samples x 17 correlated inputs, every 5th held out (7,001 train,
1,751 test), in the benchmark format (X_train, y_train, X_test, y_test; float64).
Usage: /usr/bin/python3 bench/synthetic17.py OUT.h5"""
import sys
import h5py
import numpy as np

rng = np.random.default_rng(17)
n, d = 8752, 17
# Correlated inputs (a random linear map of standard normals), as robot states and controls are.
mix = np.eye(d) + 0.3 * rng.standard_normal((d, d))
x = rng.standard_normal((n, d)) @ mix.T
w = rng.standard_normal(d) / np.sqrt(d)
y = np.sin(x[:, 0]) + 0.5 * np.cos(1.5 * x[:, 3]) * x[:, 5] + np.tanh(x @ w) + 0.1 * rng.standard_normal(n)
test = np.arange(n) % 5 == 0
y = (y - y[~test].mean()) / y[~test].std()
with h5py.File(sys.argv[1], "w") as f:
    f["X_train"], f["y_train"] = x[~test], y[~test]
    f["X_test"], f["y_test"] = x[test], y[test]
    f.attrs["name"] = "synthetic17"
print(x[~test].shape, x[test].shape)
