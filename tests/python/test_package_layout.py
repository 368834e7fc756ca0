"""The eyerender package's layering, read from its sources with ast (nothing is imported): the modules import one
another without a cycle, and none reaches into another module's underscore-private names."""
import ast
import pathlib

PACKAGE_DIR = pathlib.Path(__file__).resolve().parents[2] / "python" / "eyerender"
PACKAGE = "eyerender"
EXTENSION = "_hdeye"  # the compiled bindings: a private module by convention, the package's wrappers import it


def module_name(path):
    return PACKAGE if path.stem == "__init__" else f"{PACKAGE}.{path.stem}"


def parse_package():
    """{module name: ast tree} of every source module of the package."""
    return {module_name(p): ast.parse(p.read_text(), filename=str(p)) for p in sorted(PACKAGE_DIR.glob("*.py"))}


def imports_of(tree, modules):
    """[(imported module, imported names, line)] of every import in `tree` (function-level ones too: a cycle
    through a lazy import is still a cycle), restricted to the package's own modules."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(a.name, [], node.lineno) for a in node.names if a.name in modules]
        elif isinstance(node, ast.ImportFrom):
            base = PACKAGE if node.level else node.module or ""
            if node.level and node.module:
                base = f"{PACKAGE}.{node.module}"
            names = [a.name for a in node.names]
            submodules = [f"{base}.{n}" for n in names if f"{base}.{n}" in modules]  # from . import farm_tasks
            found += [(m, [], node.lineno) for m in submodules]
            rest = [n for n in names if f"{base}.{n}" not in modules]
            if rest and (base in modules or base == f"{PACKAGE}.{EXTENSION}"):
                found.append((base, rest, node.lineno))
    return found


def import_graph(trees):
    """{module: {imported module: first line}}; importing a submodule also runs the package's __init__, but that
    edge is the interpreter's, not the module's, so only written imports count."""
    graph = {}
    for name, tree in trees.items():
        edges = graph.setdefault(name, {})
        for target, _, line in imports_of(tree, trees):
            if target != name:
                edges.setdefault(target, line)
    return graph


def find_cycle(graph):
    """One import cycle as a list of modules (first == last), or None."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for target in sorted(graph.get(node, ())):
            if state.get(target) == "open":
                return stack[stack.index(target):] + [target]
            if target not in state:
                cycle = visit(target)
                if cycle:
                    return cycle
        state[node] = "done"
        stack.pop()
        return None

    for node in sorted(graph):
        if node not in state:
            cycle = visit(node)
            if cycle:
                return cycle
    return None


def is_private(name):
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def test_the_package_is_read_whole():
    trees = parse_package()
    assert {"eyerender", "eyerender.eyerecord", "eyerender.job", "eyerender.farm", "eyerender.farm_tasks",
            "eyerender.farm_cli", "eyerender.study"} <= set(trees), sorted(trees)
    graph = import_graph(trees)
    assert "eyerender.job" in graph["eyerender.eyerecord"] and "eyerender.job" in graph["eyerender.farm_tasks"], \
        graph  # the reader sees lazy (function-level) imports too


def test_cycle_finder_finds_a_cycle_through_a_lazy_import():
    source = {"eyerender.a": "from .b import f\n", "eyerender.b": "def f():\n    from . import a\n"}
    graph = import_graph({name: ast.parse(text) for name, text in source.items()})
    assert find_cycle(graph) == ["eyerender.a", "eyerender.b", "eyerender.a"], graph


def test_modules_import_one_another_without_a_cycle():
    graph = import_graph(parse_package())
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(
        f"{a} (line {graph[a][b]})" for a, b in zip(cycle, cycle[1:])) + f" -> {cycle[-1]}"


def test_no_module_imports_another_modules_private_names():
    trees = parse_package()
    offences = [f"{name} line {line}: {target}.{n}" for name, tree in trees.items()
                for target, names, line in imports_of(tree, trees) for n in names if is_private(n)]
    assert not offences, offences


def test_no_module_reads_private_attributes_of_another_modules_objects():
    """obj._name is allowed on self, cls and the module's own classes, nowhere else."""
    offences = []
    for name, tree in parse_package().items():
        own = {"self", "cls"} | {n.name for n in ast.walk(tree) if isinstance(n, ast.ClassDef)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and is_private(node.attr) and \
                    not (isinstance(node.value, ast.Name) and node.value.id in own):
                offences.append(f"{name} line {node.lineno}: {ast.unparse(node)}")
    assert not offences, offences
