"""Dependencies point one way: down the layers, and navigation and behaviours load no simulator."""
from __future__ import annotations

import ast
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import ravh_sim.behaviours

SIMULATOR_MODULES = ("pybullet", "moderngl", "ravh_sim.world.scene", "ravh_sim.world.furniture",
                     "ravh_sim.robot.robot")
ROOT = Path(__file__).resolve().parents[1]
BEHAVIOUR_NODES = ["ravh_sim.nodes.behaviour_node", "ravh_sim.nodes.wanderer_node", "ravh_sim.nodes.grid_node",
                   "ravh_sim.nodes.teleop_node"]
BEHAVIOURS = [f"ravh_sim.behaviours.{m.name}" for m in pkgutil.iter_modules(ravh_sim.behaviours.__path__)]


def _loaded_simulator_modules(modules: list[str]) -> list[str]:
    """The simulator modules that importing ``modules`` in a fresh interpreter loads."""
    probe = (f"import sys\nfor m in {modules!r}: __import__(m)\n"
             f"print(','.join(m for m in {SIMULATOR_MODULES!r} if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120,
                          cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return [m for m in done.stdout.strip().split(",") if m]


@pytest.mark.parametrize("modules", [["ravh_sim.nav.follower"], BEHAVIOURS, BEHAVIOUR_NODES],
                         ids=["follower", "behaviours", "behaviour_nodes"])
def test_navigation_and_behaviours_load_no_simulator(modules):
    assert len(modules) > 0
    assert _loaded_simulator_modules(modules) == []


def test_the_probe_sees_a_simulator_module_when_one_is_loaded():
    loaded = _loaded_simulator_modules(["ravh_sim.robot.robot"])
    assert "pybullet" in loaded and "ravh_sim.robot.robot" in loaded


# --------------------------------------------------------------------------- import cycles

PACKAGES = ("ravh_sim", "ravh_msgs_py")


def _modules() -> dict[str, Path]:
    """Every module of our packages by dotted name (a package by its name, for its __init__)."""
    found = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """Our modules that ``name`` imports anywhere in its text: at the top, inside functions and under
    TYPE_CHECKING alike (an import hidden in a function still makes the arrow point back), and the
    packages those live in (importing a.b.c runs a/__init__ and a/b/__init__ first)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    targets = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                base = f"{anchor}.{base}" if base else anchor
            targets.add(base)
            targets.update(f"{base}.{alias.name}" for alias in node.names)
    found = set()
    for target in targets:
        parts = target.split(".")
        found.update(".".join(parts[:i]) for i in range(1, len(parts) + 1))
    return {t for t in found if t in modules and t != name and not name.startswith(t + ".")}


def import_graph() -> dict[str, set[str]]:
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle as [a, b, ..., a], or None (iterative depth-first search)."""
    state: dict[str, int] = {}                      # 1 on the current path, 2 done
    for root in sorted(graph):
        if root in state:
            continue
        path, stack = [root], [iter(sorted(graph[root]))]
        state[root] = 1
        while stack:
            nxt = next(stack[-1], None)
            if nxt is None:
                state[path.pop()] = 2
                stack.pop()
            elif state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            elif nxt not in state:
                state[nxt] = 1
                path.append(nxt)
                stack.append(iter(sorted(graph[nxt])))
    return None


def test_the_package_has_no_import_cycle():
    graph = import_graph()
    assert "ravh_sim.nav.follower" in graph and "ravh_sim.poses" in graph["ravh_sim.nav.follower"]
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_the_cycle_finder_finds_a_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"b", "d"}, "d": set()}
    assert find_cycle(graph) == ["b", "c", "b"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None


# --------------------------------------------------------------------------- layers

# Lowest first: a module may import from its own layer and the layers below it, never from above, so
# each layer can be read, tested and reused without those above it. Modules belong to the layer of
# their longest listed prefix; packages named together in one layer are peers that import each other.
LAYERS: list[tuple[str, ...]] = [
    ("ravh_msgs_py", "ravh_sim", "ravh_sim.errors", "ravh_sim.paths", "ravh_sim.files", "ravh_sim.poses",
     "ravh_sim.schema", "ravh_sim.paper"),
    ("ravh_sim.world",),                         # the house and its physics, told which backend draws it
    ("ravh_sim.look",),                          # what the camera should see: geometry, materials, lights
    ("ravh_sim.render",),                        # draws the scene description; whoever builds both resolves the backend
    ("ravh_sim.sensors",),                       # each declares its profile section, files and topics
    ("ravh_sim.nav",),                           # maps and paths; reads a robot's size and limits via Protocols
    ("ravh_sim.robot",),                         # a profile's body in the physics; agents start on nav's free space
    ("ravh_sim.dataset",),                       # the format: written and read through the sensor ports
    ("ravh_sim.viz",),                           # pictures of a house
    ("ravh_sim.behaviours",),
    ("ravh_sim.runtime",),                       # the simulation without ROS
    ("ravh_sim.nodes",),
    ("ravh_sim.raids",),                         # recording datasets: ROS processes or one direct process
    ("ravh_sim.eval",),                          # the paper's experiments, over recorded datasets
    ("ravh_sim.importers",),                     # offline converters to houses and the library; no runtime use
    ("ravh_sim.bench", "ravh_sim.bench_ros", "ravh_sim.cli"),
]


def layer_of(module: str, layers: list[tuple[str, ...]]) -> int:
    """The index of the layer that ``module`` belongs to (its longest listed prefix)."""
    owners = [(len(prefix), i) for i, layer in enumerate(layers) for prefix in layer
              if module == prefix or module.startswith(prefix + ".")]
    if not owners:
        raise KeyError(f"{module} is in no layer: add it to LAYERS")
    return max(owners)[1]


def back_arrows(graph: dict[str, set[str]], layers: list[tuple[str, ...]]) -> list[str]:
    """The imports that point up: from a module to one in a higher layer, as "a -> b"."""
    return sorted(f"{a} -> {b}" for a, targets in graph.items() for b in targets
                  if layer_of(b, layers) > layer_of(a, layers))


def test_imports_point_down_the_layers():
    graph = import_graph()
    assert "ravh_sim.raids.raid" in graph and "ravh_sim.nodes.common" in graph["ravh_sim.raids.raid"]
    arrows = back_arrows(graph, LAYERS)
    assert arrows == [], "imports that point up the layers:\n" + "\n".join(arrows)


def test_the_layer_check_finds_an_arrow_pointing_up():
    layers = [("base",), ("mid", "peer"), ("top",)]
    graph = {"base.a": {"base.b"}, "base.b": set(), "mid.x": {"base.a", "peer.y"}, "peer.y": {"mid.x"},
             "top": {"mid.x", "base.b"}}
    assert back_arrows(graph, layers) == []
    graph["base.b"] = {"mid.x"}
    assert back_arrows(graph, layers) == ["base.b -> mid.x"]
    assert layer_of("mid.x.deep", layers) == 1
    with pytest.raises(KeyError, match="elsewhere"):
        layer_of("elsewhere", layers)


# --------------------------------------------------------------------------- who talks to pybullet

# The World owns the client (bodies of the house, ray casts); a robot builds and drives its own body
# on it, the Simulation steps it, and the TinyRenderer draws through it (its visual mirror of the
# world's bodies, tiny_scene, lives in the same client). Nothing else calls pybullet:
# sensors ask the World or a renderer (ravh_sim.render), so a physics or renderer change stays there.
PYBULLET_OWNERS = {"ravh_sim.world.scene", "ravh_sim.robot.robot", "ravh_sim.robot.simulation",
                   "ravh_sim.render.tiny_renderer", "ravh_sim.render.tiny_scene"}


def _imports_pybullet(path: Path) -> bool:
    return any(isinstance(node, ast.Import) and any(a.name == "pybullet" for a in node.names)
               or isinstance(node, ast.ImportFrom) and node.module == "pybullet"
               for node in ast.walk(ast.parse(path.read_text(), str(path))))


def test_only_the_client_owners_import_pybullet():
    users = {name for name, path in _modules().items() if _imports_pybullet(path)}
    assert "ravh_sim.world.scene" in users
    assert users == PYBULLET_OWNERS
