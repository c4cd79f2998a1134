"""The package's documentation and type stubs: help(diffpills) explains the API, every public
name has a docstring, and the stubs declare exactly the module's public names."""

import ast
import pathlib
import pydoc

import diffpills
import diffpills.torch


def test_help_describes_the_api():
    text = pydoc.render_doc(diffpills, renderer=pydoc.plaintext)
    for words in ("proximity_batch", "PaddedPolygon", "phi", "gradient", "ValueError", "diffpills.torch"):
        assert words in text
    for name in diffpills.__all__:
        if name != "__version__":
            assert getattr(diffpills, name).__doc__, name
    assert diffpills.torch.proximity.__doc__


def _stub_names(path):
    tree = ast.parse(path.read_text())
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    return names


def test_stubs_match_the_modules():
    folder = pathlib.Path(diffpills.__file__).parent
    assert (folder / "py.typed").exists()
    core_stub = _stub_names(folder / "_core.pyi")
    assert set(diffpills.__all__) <= core_stub
    public = {n for n in dir(diffpills._core) if not n.startswith("_")} | {"__version__"}
    assert public <= core_stub
    assert _stub_names(folder / "torch.pyi") >= set(diffpills.torch.__all__)


def test_version_matches_the_project():
    cmake = (pathlib.Path(__file__).parents[2] / "CMakeLists.txt").read_text()
    assert f"VERSION {diffpills.__version__}" in cmake
