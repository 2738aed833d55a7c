"""An engine whose results say the topology was not kept.

The engine keeps the topology on every input known: a pass its repairs leave broken is redone as
collapses from the whole mesh (native decimate.cpp). The reports of a result that did not keep it
(command line, batch, Blender) are tested on results whose final check is made to say so.
"""


def reporting_lost_components(monkeypatch, engine, lost=2):
    """Until the test ends, engine.decimate's results say `lost` components were lost."""
    decimate = engine.decimate

    def broken(*args, **kwargs):
        raw = decimate(*args, **kwargs)
        raw["output_check"] = {**raw["output_check"], "lost_components": lost}
        return raw

    monkeypatch.setattr(engine, "decimate", broken)
