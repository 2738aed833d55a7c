"""The batch without Blender: settings, one task per asset (serially or on Dask), mesh-file
assets, the manifest a rerun skips by, LOD pruning and screen-size targets."""
