"""The package imports from the build tree and says which library it binds."""

import gpilqg


def test_version_is_the_librarys():
    assert isinstance(gpilqg.__version__, str)
    assert gpilqg.__version__.count(".") == 2


def test_errors_are_value_errors():
    assert issubclass(gpilqg.InputError, ValueError)
    assert issubclass(gpilqg.DataError, gpilqg.InputError)
