"""MeasurementSet to and from pandas DataFrames with the columns of the CSV format
(docs/formats.md#measurement-data-csv-and-hdf5): episode, t, the state names, the control names."""


def _from_dataframe(df, system):
    """A MeasurementSet from a DataFrame with columns episode, t, <states>, <controls> (any order;
    other columns are an error that lists both sets, as the CSV reader's is)."""
    from . import _gpilqg

    dynamics = _gpilqg.system(system) if isinstance(system, str) else system
    expected = ["episode", "t"] + list(dynamics.state_names) + list(dynamics.control_names)
    if sorted(df.columns) != sorted(expected):
        raise _gpilqg.InputError("DataFrame columns %s; expected %s" % (list(df.columns), expected))
    episodes, ids = [], []
    for episode, rows in df.groupby("episode", sort=False):
        ids.append(int(episode))
        episodes.append((rows["t"].to_numpy(dtype=float), rows[list(dynamics.state_names)].to_numpy(dtype=float),
                         rows[list(dynamics.control_names)].to_numpy(dtype=float)))
    return _gpilqg.MeasurementSet(system, episodes, ids)


def _to_dataframe(self):
    """The set as a DataFrame with the CSV format's columns, one row per sample."""
    import numpy as np
    import pandas as pd

    frames = []
    for e in self.episodes:
        frame = pd.DataFrame(np.hstack([e.x, e.u]), columns=list(self.state_names) + list(self.control_names))
        frame.insert(0, "t", e.t)
        frame.insert(0, "episode", e.id)
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def install(cls):
    cls.from_dataframe = staticmethod(_from_dataframe)
    cls.to_dataframe = _to_dataframe
