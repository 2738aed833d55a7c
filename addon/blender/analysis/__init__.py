"""The analysis panels' data: topology (invariants, handle and tunnel loops) and metrics
(Hausdorff distance, triangle quality)."""
