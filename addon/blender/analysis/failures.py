"""How the analysis panels keep a failure: its message stored with the results, then raised."""

from contextlib import contextmanager


@contextmanager
def stored_failure(results, error_class: type):
    """Runs the block; an ``error_class`` it raises is stored on ``results`` (state ERROR, the
    message, a new revision so the panel redraws) and raised again."""
    try:
        yield
    except error_class as error:
        results.state, results.message = "ERROR", str(error)
        results.revision += 1
        raise
