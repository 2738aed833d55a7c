"""Batch decimation in Blender (docs/design.md §6):

    blender -b --factory-startup --python-exit-code 1 --python build/python/topstoc/batch.py -- \\
        --input FILE_OR_DIR... (--ratio R | --vertices N | --triangles N | --max-error E[%]) [--seed S] \\
        --output DIR [--json REPORT.json]

A thin launcher: puts the folder holding this package on sys.path, then runs
topstoc.blender.batch.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from topstoc.blender.batch import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
