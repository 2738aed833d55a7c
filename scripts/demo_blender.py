"""Blender side of scripts/demo.sh: runs topstoc.blender.demo from the staged build.

    blender -b --factory-startup --python-exit-code 1 --python scripts/demo_blender.py -- \
        --input MESH --ratio R --output DIR
"""

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.environ.get("TOPSTOC_BUILD", os.path.join(ROOT, "build")), "python"))

from topstoc.blender.demo import main  # noqa: E402

sys.exit(main())
