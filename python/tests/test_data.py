"""Measurement sets from Python: arrays, files and DataFrames, read-only views, and the library's errors."""

import numpy as np
import pandas as pd
import pytest

import gpilqg
from conftest import SOURCE_DIR


def episode(T=20, dt=0.02, seed=0):
    rng = np.random.default_rng(seed)
    return np.arange(T) * dt, rng.normal(size=(T, 4)), rng.normal(size=(T, 1))


def test_from_arrays_shapes_dtypes_and_views():
    t, x, u = episode()
    s = gpilqg.MeasurementSet("cartpole", [(t, x, u), episode(seed=1)], ids=[3, 7])
    assert s.system == "cartpole"
    assert s.sample_count == 40
    assert [e.id for e in s.episodes] == [3, 7]
    e = s.episodes[0]
    np.testing.assert_array_equal(e.x, x)
    assert e.x.shape == (20, 4) and e.u.shape == (20, 1) and e.t.shape == (20,)
    assert e.x.dtype == np.float64
    # A view of the set's memory, not a copy: two reads share memory, and it cannot be written.
    assert np.shares_memory(s.episodes[0].x, s.episodes[0].x)
    assert not e.x.flags.writeable
    assert e.dt == pytest.approx(0.02)


def test_bad_arrays_raise_input_errors_naming_the_episode():
    t, x, u = episode()
    with pytest.raises(gpilqg.InputError, match="episode 0: x is 20 x 3"):
        gpilqg.MeasurementSet("cartpole", [(t, x[:, :3], u)])
    bad = x.copy()
    bad[5, 2] = np.nan
    with pytest.raises(gpilqg.InputError, match=r"episode 0: x\(5, 2\) = nan is not finite"):
        gpilqg.MeasurementSet("cartpole", [(t, bad, u)])
    with pytest.raises(gpilqg.InputError, match="episode 0, sample"):
        gpilqg.MeasurementSet("cartpole", [(t[::-1].copy(), x, u)])


def test_write_and_read_round_trip_bit_for_bit(tmp_path):
    s = gpilqg.MeasurementSet("cartpole", [episode(seed=2), episode(seed=3)])
    for name in ("set.csv", "set.h5"):
        s.write(tmp_path / name)
        back = gpilqg.read_measurements(tmp_path / name, "cartpole")
        for a, b in zip(s.episodes, back.episodes):
            np.testing.assert_array_equal(a.x, b.x)
            np.testing.assert_array_equal(a.u, b.u)


def test_reading_a_bad_file_raises_a_data_error_naming_the_line(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("episode,t,x,x_dot,theta,theta_dot,force\n0,0.0,0,0,0,0,0\n0,0.02,0,0,oops,0,0\n")
    with pytest.raises(gpilqg.DataError, match="bad.csv:line 3"):
        gpilqg.read_measurements(bad, "cartpole")


def test_dataframe_round_trip_and_the_shipped_csv():
    s = gpilqg.read_measurements(SOURCE_DIR / "data" / "cartpole_hidden_friction.csv", "cartpole")
    df = s.to_dataframe()
    assert list(df.columns) == ["episode", "t", "x", "x_dot", "theta", "theta_dot", "force"]
    assert len(df) == s.sample_count
    back = gpilqg.MeasurementSet.from_dataframe(df, "cartpole")
    for a, b in zip(s.episodes, back.episodes):
        np.testing.assert_array_equal(a.x, b.x)
        np.testing.assert_array_equal(a.t, b.t)
    pd_csv = pd.read_csv(SOURCE_DIR / "data" / "cartpole_hidden_friction.csv", float_precision="round_trip")
    np.testing.assert_array_equal(gpilqg.MeasurementSet.from_dataframe(pd_csv, "cartpole").episodes[0].x,
                                  s.episodes[0].x)
    with pytest.raises(gpilqg.InputError, match="expected"):
        gpilqg.MeasurementSet.from_dataframe(df.drop(columns=["theta"]), "cartpole")


def test_a_passive_system_has_no_control_columns(tmp_path):
    # The passive pendulum (no actuators): episodes are (t, x), u has shape (T, 0), files have no control columns.
    pendulum = str(SOURCE_DIR / "data" / "pendulum_passive.xml")
    t = np.arange(10) * 0.02
    x = np.random.default_rng(0).normal(size=(10, 2))
    s = gpilqg.MeasurementSet(pendulum, [(t, x), (t, x, np.zeros((10, 0)))])
    assert s.control_names == [] and s.state_names == ["swing", "swing_dot"]
    assert s.episodes[0].u.shape == (10, 0)
    for name in ("swing.csv", "swing.h5"):
        s.write(tmp_path / name)
        back = gpilqg.read_measurements(tmp_path / name, pendulum)
        np.testing.assert_array_equal(back.episodes[1].x, x)
        assert back.episodes[1].u.shape == (10, 0)
    assert (tmp_path / "swing.csv").read_text().splitlines()[0] == "episode,t,swing,swing_dot"
    df = s.to_dataframe()
    assert list(df.columns) == ["episode", "t", "swing", "swing_dot"]
    again = gpilqg.MeasurementSet.from_dataframe(df, pendulum)
    np.testing.assert_array_equal(again.episodes[0].x, x)
    # A system with controls still needs them.
    with pytest.raises(gpilqg.InputError, match=r"expected a tuple \(t, x, u\)"):
        gpilqg.MeasurementSet("cartpole", [(t, np.zeros((10, 4)))])
