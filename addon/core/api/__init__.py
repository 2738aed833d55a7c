"""The public API on numpy arrays: the prepared mesh, the decimation job and its runs, topology,
loops, edits, clean-up and Hausdorff distance (topstoc.core re-exports the public names)."""
