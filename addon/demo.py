"""Demo: guided decimation of a real mesh, written as .blend, .obj and a PNG render.

    blender -b --factory-startup --python-exit-code 1 --python build/python/topstoc/demo.py -- \\
        [--input MESH.obj] [--ratio 0.1] --output DIR

A thin launcher: puts the folder holding this package on sys.path, then runs
topstoc.blender.demo.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from topstoc.blender.demo import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
