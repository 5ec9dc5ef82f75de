"""Issue 23: ``scenario`` first everywhere (the earlier orders, accepted with a warning up to 0.2, are gone in 0.3).

The test scans the package: no public function has a positional ``scenario``
that is not first (independent count: the AST).
"""

import ast
import pathlib

import hinfnav


def test_no_public_function_has_a_positional_scenario_after_another_parameter():
    root = pathlib.Path(hinfnav.__file__).parent
    late = []
    for path in root.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
                pos = [a.arg for a in node.args.posonlyargs + node.args.args if a.arg not in ("self", "cls")]
                if "scenario" in pos[1:]:
                    late.append(f"{path.relative_to(root)}:{node.lineno} {node.name}")
    assert late == []
