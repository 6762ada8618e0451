"""The type stub shipped in the wheel (`drumroll.pyi`) declares everything the module has: every
public function and class, and every public method, property and attribute of each class,
so that an editor shows all of it."""

import ast
import pathlib

import drumroll

STUB = pathlib.Path(__file__).resolve().parents[1] / "drumroll.pyi"


def _declared():
    """The stub's module-level names, and for each class the names declared in its body."""
    tree = ast.parse(STUB.read_text())
    names, members = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
        if isinstance(node, ast.ClassDef):
            body = set()
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    body.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    body.add(item.target.id)
            members[node.name] = body
    return names, members


def _public(names):
    return {n for n in names if not n.startswith("_")}


def test_the_stub_declares_every_public_name_of_the_module():
    names, members = _declared()
    missing = _public(dir(drumroll)) - names - {"drumroll"}
    assert not missing, f"drumroll.pyi lacks {sorted(missing)}"
    for name in _public(dir(drumroll)):
        cls = getattr(drumroll, name)
        if not isinstance(cls, type):
            continue
        lacking = _public(dir(cls)) - members.get(name, set())
        assert not lacking, f"drumroll.pyi's {name} lacks {sorted(lacking)}"
