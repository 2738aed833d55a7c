"""One guided decimation of a Blender object: the pipeline every front end calls, the guidance
sources it reads, and normal-map bakes of its results."""
