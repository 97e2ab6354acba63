"""Dicts of TOML tables written as TOML text, for configs given as dicts."""

import json
import math


def _value(value, where):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        if isinstance(value, float) and not math.isfinite(value):
            raise ValueError("%s: %r is not a finite number" % (where, value))
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string
    if hasattr(value, "tolist"):  # NumPy arrays and scalars
        return _value(value.tolist(), where)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v, where) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join("%s = %s" % (json.dumps(k), _value(v, where)) for k, v in value.items()) + "}"
    raise TypeError("%s: cannot write %s as TOML" % (where, type(value).__name__))


def to_toml(config):
    """{"table": {"key": value}, "tasks": [{...}, ...]} -> TOML text (tables, arrays of tables)."""
    lines = []
    for name, table in config.items():
        if isinstance(table, (list, tuple)) and all(isinstance(t, dict) for t in table):
            for item in table:
                lines.append("[[%s]]" % name)
                lines += ["%s = %s" % (k, _value(v, "%s.%s" % (name, k))) for k, v in item.items()]
        elif isinstance(table, dict):
            lines.append("[%s]" % name)
            lines += ["%s = %s" % (json.dumps(k) if "." in k else k, _value(v, "%s.%s" % (name, k)))
                      for k, v in table.items()]
        else:
            raise TypeError("config: %r must be a table (dict) or an array of tables" % name)
    return "\n".join(lines) + "\n"
