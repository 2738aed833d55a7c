"""The Dask runner's packages are the `topstoc[cluster]` extra, and the error raised when they are
missing names that extra (issue 38: `pip install topstoc` then `topstoc batch --workers 2`)."""

import os
import subprocess
import sys
import tomllib

import pytest

import cli
from conftest import BUILD, ROOT, DATA
from topstoc.core.batch import run as batch_run
from topstoc.core.support.errors import TopStocError

INSTALL_HINT = 'pip install "topstoc[cluster]"'
#: Runs the command line with Dask's packages hidden: a None entry in sys.modules makes
#: `import distributed` raise ImportError, as on a machine without them.
WITHOUT_DASK = ("import sys; sys.modules['distributed'] = sys.modules['dask'] = None; "
                "from topstoc.core.cli import main; sys.exit(main(sys.argv[1:]))")


def test_pyproject_declares_the_cluster_extra():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    names = {requirement.split("[")[0].split(">")[0].split("=")[0].strip()
             for requirement in project["optional-dependencies"]["cluster"]}
    assert names == {"dask", "distributed", "tqdm"}
    assert not any(r.startswith(("dask", "distributed", "tqdm")) for r in project["dependencies"])
    # the extras table holds extras only (a key after it in the file would land inside it)
    assert set(project["optional-dependencies"]) == {"cluster"}
    assert project["classifiers"]


def test_run_dask_without_dask_names_the_extra(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(TopStocError) as raised:
        batch_run.run_dask([(0, "a.obj")], str(tmp_path), None, None, lambda *_: None, workers=2)
    assert INSTALL_HINT in str(raised.value) and "--workers 0" in str(raised.value)


def test_batch_command_without_dask_fails_in_one_line_naming_the_extra(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
    done = subprocess.run([sys.executable, "-c", WITHOUT_DASK, "batch", "--input",
                           str(DATA / "genus_positive" / "cgal_elephant.off"), "--output", str(tmp_path / "out"),
                           "--ratio", "0.5", "--workers", "2"], capture_output=True, text=True, env=env, timeout=120)
    cli.assert_one_error_line("batch", done, INSTALL_HINT)
    assert not list((tmp_path / "out").glob("*.off"))  # nothing decimated
