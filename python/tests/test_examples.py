"""The examples run: the Dask example gets the serial loop's numbers on a LocalCluster of two
worker processes, and the Fig. 2 notebook executes."""

import pathlib
import subprocess
import sys

import nbformat
from nbclient import NotebookClient

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def test_dask_example_matches_the_serial_loop():
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "dask_orbits.py")],
        capture_output=True, text=True, timeout=300,
    )
    assert result.returncode == 0, result.stderr
    print(result.stdout)
    assert "identical to the serial loop" in result.stdout


def test_figure2_notebook_executes(tmp_path):
    notebook = nbformat.read(EXAMPLES / "figure2.ipynb", as_version=4)
    NotebookClient(
        notebook, timeout=300, kernel_name="python3",
        resources={"metadata": {"path": str(tmp_path)}},
    ).execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert (tmp_path / "figure2.png").stat().st_size > 10_000
    assert (tmp_path / "regime_map.png").stat().st_size > 10_000
