"""Reading and writing Blender data: meshes, DNA arrays, edits written back, what follows a source
object onto its result, and Blender's own scene file formats."""
