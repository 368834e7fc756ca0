"""The eyerender package's layering, read from its sources with ast (nothing is imported), subpackages included: the
modules import one another without a cycle, none reaches into another module's underscore-private names, and the
code stays in small pieces (no function over MAX_FUNCTION_LINES lines, no file over MAX_FILE_LINES)."""
import ast
import pathlib

PACKAGE_DIR = pathlib.Path(__file__).resolve().parents[2] / "python" / "eyerender"
PACKAGE = "eyerender"
EXTENSION = f"{PACKAGE}._hdeye"  # the compiled bindings: a private module by convention, the wrappers import it
MAX_FUNCTION_LINES = 100  # def line to last line, decorators and docstring included
MAX_FILE_LINES = 600


def source_files():
    """Every .py file of the package, subpackages included."""
    return sorted(PACKAGE_DIR.rglob("*.py"))


def module_name(path):
    """eyerender.farm.tasks for farm/tasks.py; a package's __init__.py is the package (eyerender.farm)."""
    parts = path.relative_to(PACKAGE_DIR).with_suffix("").parts
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join((PACKAGE, *parts))


def parse_package():
    """{module name: ast tree} of every source module of the package."""
    return {module_name(p): ast.parse(p.read_text(), filename=str(p)) for p in source_files()}


def packages_of(trees):
    """The names in `trees` that are packages (some other module's name starts with theirs)."""
    return {n for n in trees if any(m.startswith(n + ".") for m in trees)} | {PACKAGE}


def import_base(node, importer, packages):
    """The module a `from ... import` statement in module `importer` imports from (relative levels resolved)."""
    if not node.level:
        return node.module or ""
    parts = importer.split(".")
    package = parts if importer in packages else parts[:-1]  # a package's level 1 is itself
    base = ".".join(package[:len(package) - (node.level - 1)])
    return f"{base}.{node.module}" if node.module else base


def imports_of(tree, modules, importer=PACKAGE, packages=(PACKAGE,)):
    """[(imported module, imported names, line)] of every import in `tree`, the source of module `importer`
    (function-level ones too: a cycle through a lazy import is still a cycle), restricted to the package's own
    modules."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(a.name, [], node.lineno) for a in node.names if a.name in modules]
        elif isinstance(node, ast.ImportFrom):
            base = import_base(node, importer, packages)
            names = [a.name for a in node.names]
            submodules = [f"{base}.{n}" for n in names if f"{base}.{n}" in modules]  # from . import tasks
            found += [(m, [], node.lineno) for m in submodules]
            rest = [n for n in names if f"{base}.{n}" not in modules]
            if rest and (base in modules or base == EXTENSION):
                found.append((base, rest, node.lineno))
    return found


def import_graph(trees):
    """{module: {imported module: first line}}; importing a submodule also runs the package's __init__, but that
    edge is the interpreter's, not the module's, so only written imports count."""
    graph, packages = {}, packages_of(trees)
    for name, tree in trees.items():
        edges = graph.setdefault(name, {})
        for target, _, line in imports_of(tree, trees, name, packages):
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
    assert {"eyerender", "eyerender.cli.eyerecord", "eyerender.job", "eyerender.farm", "eyerender.farm.tasks",
            "eyerender.cli.farm", "eyerender.cli.eyestudy", "eyerender.adapters.mesh"} <= set(trees), sorted(trees)
    graph = import_graph(trees)
    # Relative imports resolve from the subpackage: farm/tasks.py's `from ..job` is eyerender.job, `from .merge`
    # eyerender.farm.merge; the reader sees lazy (function-level) imports too (cli/eyerecord.py's `from .farm`).
    assert {"eyerender.job", "eyerender.farm.merge"} <= set(graph["eyerender.farm.tasks"]), graph
    assert "eyerender.cli.farm" in graph["eyerender.cli.eyerecord"], graph
    assert "eyerender.farm.cluster" in graph["eyerender.farm"], graph  # a package's `from .cluster`


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
    packages = packages_of(trees)
    offences = [f"{name} line {line}: {target}.{n}" for name, tree in trees.items()
                for target, names, line in imports_of(tree, trees, name, packages) for n in names if is_private(n)]
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


def test_relative_imports_resolve_from_the_importing_module():
    trees = {name: ast.parse(text) for name, text in {
        "eyerender": "", "eyerender.job": "", "eyerender.farm": "from .job import J\n",
        "eyerender.farm.job": "from ..job import _private\n", "eyerender.farm.tasks": "from . import job\n"}.items()}
    graph = import_graph(trees)
    assert graph["eyerender.farm"] == {"eyerender.farm.job": 1}, graph
    assert graph["eyerender.farm.job"] == {"eyerender.job": 1}, graph
    assert graph["eyerender.farm.tasks"] == {"eyerender.farm.job": 1}, graph
    packages = packages_of(trees)
    assert imports_of(trees["eyerender.farm.job"], trees, "eyerender.farm.job", packages) == \
        [("eyerender.job", ["_private"], 1)]


def long_functions(tree, limit):
    """[(name, first line, lines)] of the functions and methods of `tree` longer than `limit` lines (decorators
    included: what a reader scrolls through)."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            lines = node.end_lineno - first + 1
            if lines > limit:
                found.append((node.name, first, lines))
    return found


def test_the_length_check_sees_a_long_method():
    body = "\n".join(f"        x = {k}" for k in range(5))
    tree = ast.parse(f"class A:\n    @staticmethod\n    def f():\n{body}\n\ndef g():\n    pass\n")
    assert long_functions(tree, 6) == [("f", 2, 7)]
    assert long_functions(tree, 7) == []


def test_no_function_is_over_the_line_limit():
    offences = [f"{path.relative_to(PACKAGE_DIR)} line {line}: {name} has {lines} lines"
                for path in source_files()
                for name, line, lines in long_functions(ast.parse(path.read_text()), MAX_FUNCTION_LINES)]
    assert not offences, offences


def test_no_file_is_over_the_line_limit():
    lengths = {str(path.relative_to(PACKAGE_DIR)): len(path.read_text().splitlines()) for path in source_files()}
    assert len(lengths) > 40, lengths  # the package was found
    offences = {name: n for name, n in lengths.items() if n > MAX_FILE_LINES}
    assert not offences, offences
