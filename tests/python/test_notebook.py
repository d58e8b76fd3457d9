# SPDX-License-Identifier: Apache-2.0
# docs/notebooks/chromatrace.ipynb, docs/python.md's worked example, executed as a reader runs it (nbclient, a real
# IPython kernel): every cell runs without an error or a warning, and each shows what its text says it shows.
import nbformat
from nbclient import NotebookClient

from conftest import SOURCE

NOTEBOOK = SOURCE / "docs" / "notebooks" / "chromatrace.ipynb"


def text_of(cell):
    return "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream" and o.name == "stdout")


def test_the_worked_notebook_runs_and_shows_its_results():
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    NotebookClient(notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}).execute()
    code = [c for c in notebook.cells if c.cell_type == "code"]
    for cell in code:
        assert not [o for o in cell.outputs if o.output_type == "error"], cell.source
        assert not [o for o in cell.outputs if o.output_type == "stream" and o.name == "stderr"], (cell.source, cell.outputs)
    # The analysis shows itself as the report, in a frame of its own, with a PNG for front ends without HTML.
    shown = next(o for o in code[1].outputs if o.output_type == "execute_result")
    assert shown.data["text/html"].startswith('<iframe ') and "srcdoc=" in shown.data["text/html"]
    assert "chromatrace analysis" in shown.data["text/html"] and "image/png" in shown.data
    assert text_of(code[2]).startswith("light: RGB [")
    assert text_of(code[4]).startswith("segment 1 — ")
    spectral = text_of(code[5]).splitlines()
    assert spectral[0].startswith("spectral emissive (96, 96, ") and spectral[1].startswith("DN (96, 96, 3) exposure ")
    regions = text_of(code[6]).splitlines()
    assert regions[0].strip() == "image: volume" or regions[0].strip().startswith("image: ")
    assert any("object 6 (sphere)" in r for r in regions)
    assert [o for o in code[7].outputs if "image/png" in o.get("data", {})]
