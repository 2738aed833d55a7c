"""TopStoc's error base class: every error TopStoc raises on purpose derives from it."""


class TopStocError(ValueError):
    """A request TopStoc cannot carry out; the message names the problem.

    It is a ValueError, so code that catches ValueError keeps working. The add-on's errors
    (DecimationError, GuidanceError, AnalysisError, EditError, MetricsError) derive from it,
    so one ``except TopStocError`` catches any of them.
    """
