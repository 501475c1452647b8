"""PETSc options with a mandatory prefix, removed from the global database after use."""

from contextlib import contextmanager


@contextmanager
def petsc_options(prefix, options):
    """Put ``options`` under ``prefix`` for the duration of a ``setFromOptions`` call."""
    from petsc4py import PETSc

    db = PETSc.Options()
    for key, value in options.items():
        db[f"{prefix}{key}"] = value
    try:
        yield
    finally:
        for key in options:
            db.delValue(f"{prefix}{key}")
