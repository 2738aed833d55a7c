"""Loads the compiled engine `_topstoc`.

Where it lives depends on how TopStoc was installed:
- next to this package (build/python/topstoc, the legacy add-on zip, `pip install topstoc`);
- in the separate distribution `topstoc_native` (the Blender extension: Blender installs the
  wheel matching its Python from the extension's wheels/, and the add-on package itself holds
  no binary; see docs/packaging.md).
If neither imports, the error names the real cause (native_diagnosis).
"""

import importlib
import importlib.util
import os

from . import native_diagnosis
from .errors import TopStocError

_PACKAGE = __name__.rsplit(".", 3)[0]  # topstoc, or bl_ext.<repository>.topstoc in Blender 4.2+


def _native_distribution_dir():
    """The folder of the installed `topstoc_native` package, None when it is not installed."""
    try:
        spec = importlib.util.find_spec("topstoc_native")
    except (ImportError, ValueError):
        return None
    return list(spec.submodule_search_locations)[0] if spec and spec.submodule_search_locations else None


def _load():
    errors = []
    for name in (f"{_PACKAGE}._topstoc", "topstoc_native._topstoc"):
        try:
            return importlib.import_module(name)
        except ImportError as error:
            errors.append(error)
    package_dir = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # topstoc/
    directories = [package_dir] + [d for d in [_native_distribution_dir()] if d]
    # The first error (the module next to the package) explains a local build; when only the
    # native distribution is installed, its error is the informative one.
    error = errors[1] if native_diagnosis.candidate_files(directories[1:]) else errors[0]
    raise ImportError(native_diagnosis.explain(error, directories)) from error


engine = _load()
# Bad input the engine names (std::invalid_argument) is raised as TopStocError, a ValueError.
engine._set_error_class(TopStocError)

__all__ = ["engine"]
