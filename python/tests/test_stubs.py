"""The type stubs name exactly what the module has, and help() has something to say."""

import ast
import inspect
import pathlib

import vkpose

STUB = pathlib.Path(vkpose.__file__).with_name("__init__.pyi")
ALIASES = {"PathLike", "Progress", "DeviceArg", "ConfigArg", "CameraArg"}


def stub_tree():
    tree = ast.parse(STUB.read_text())
    names, classes = set(), {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names.add(node.name)
            classes[node.name] = {
                n.name if isinstance(n, ast.FunctionDef) else n.target.id
                for n in node.body
                if isinstance(n, ast.FunctionDef) or (isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name))
            }
        elif isinstance(node, ast.FunctionDef):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets)
    return names - ALIASES, classes


def test_stubs_name_the_module():
    names, classes = stub_tree()
    assert names == set(vkpose.__all__)
    for name, members in classes.items():
        cls = getattr(vkpose, name)
        for member in members - {"__init__"}:
            if name == "Config" and member in ("match", "cluster", "score", "nms", "detector", "initial_pose",
                                               "refine", "verify"):
                assert isinstance(getattr(vkpose.Config(), member), vkpose.ConfigSection)
                continue
            assert hasattr(cls, member), "%s.%s is in the stubs but not in the module" % (name, member)
        if issubclass(cls, Exception):
            continue
        public = {m for m in dir(cls) if not m.startswith("_")}
        assert public <= members, "%s has %s, which the stubs lack" % (name, sorted(public - members))


def test_help_is_useful():
    for obj in (vkpose, vkpose.Detector, vkpose.Detector.detect, vkpose.train, vkpose.Config, vkpose.draw,
                vkpose.Bank, vkpose.evaluate, vkpose.synth):
        assert obj.__doc__ and len(obj.__doc__) > 40, obj
    assert "rgb" in vkpose.Detector.detect.__doc__ and "GIL" in vkpose.Detector.__doc__
    assert "units" in inspect.getdoc(vkpose.train)
