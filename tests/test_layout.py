"""The package's shape, as docs/architecture.md draws it: layers that import only downwards,
modules a reader can hold in mind, and a thin command line."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).parent.parent / "pianobot"
LAYERS = ("music", "sim", "env", "pianist", "agent", "perform", "learn", "cli")
"""The layers, lowest first: each imports only from those before it (and from the package's top
modules: errors, files, config)."""
MODULE_LINES = 500
CLI_FUNCTION_LINES = 100


def _modules():
    return sorted(PACKAGE.rglob("*.py"))


def _imported(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("pianobot."):
            yield node.module, node.lineno
        elif isinstance(node, ast.Import):
            yield from ((a.name, node.lineno) for a in node.names if a.name.startswith("pianobot."))


def test_layers_import_only_downwards():
    """Lazy imports inside functions count too: a layer that reaches up makes a circle."""
    upwards = []
    for path in _modules():
        parts = path.relative_to(PACKAGE).parts
        if len(parts) < 2 or parts[0] not in LAYERS:
            continue
        level = LAYERS.index(parts[0])
        for module, line in _imported(ast.parse(path.read_text())):
            layer = module.split(".")[1]
            if layer in LAYERS and LAYERS.index(layer) > level:
                upwards.append(f"{path.relative_to(PACKAGE)}:{line} imports {module}")
    assert not upwards, "\n".join(upwards)


def test_no_module_is_longer_than_500_lines():
    long = {str(p.relative_to(PACKAGE)): n for p in _modules() if (n := len(p.read_text().splitlines())) > MODULE_LINES}
    assert not long, long


def test_no_command_line_function_is_longer_than_100_lines():
    """Each command parses its options, calls the library and prints: its work lives below cli/."""
    long = {}
    for path in sorted((PACKAGE / "cli").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - min([node.lineno, *(d.lineno for d in node.decorator_list)]) + 1
                if lines > CLI_FUNCTION_LINES:
                    long[f"{path.relative_to(PACKAGE)}:{node.name}"] = lines
    assert not long, long
