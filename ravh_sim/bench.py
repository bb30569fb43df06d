"""Benchmarks printed as JSON: absolute times plus ratios against a baseline taken in the same run.

Timed tests are flaky on a shared 2-core machine; ratios measured side by side are not. Each
``bench_*`` function returns a flat dict; ``ravh bench WHAT --json`` prints it.
"""
from __future__ import annotations

import os
import statistics
import tempfile
import time
from typing import Any, Callable

LOAD_TARGET_S = 2.0
TRIANGLE_TARGET_HOUSE23 = 60_000


def run(what: str, houses: list[int] | None = None) -> dict[str, Any]:
    benches: dict[str, Callable[..., dict[str, Any]]] = {"load": bench_load}
    return benches[what](houses=houses)


def _timed(fn: Callable[[], Any]) -> tuple[float, Any]:
    t0 = time.perf_counter()
    value = fn()
    return time.perf_counter() - t0, value


def bench_load(houses: list[int] | None = None) -> dict[str, Any]:
    """Build time (house file to a ready pybullet world) and triangle count per house.

    Baselines: the same build with an empty asset cache (first run on a machine), and a bare pybullet
    client with the renderer loaded (the fixed cost every build pays).
    """
    from ravh_sim.world.house import available_houses, load_house
    from ravh_sim.world.scene import World
    from ravh_sim.world.settings import load_settings, resolve

    settings = load_settings()
    numbers = houses or available_houses()

    def build(n: int) -> tuple[float, int]:
        def make() -> int:
            house = load_house(n)
            world = World(house, resolve(settings, house))
            tris = world.triangle_count
            world.close()
            return tris
        return _timed(make)

    build(numbers[0])                                   # warm the asset cache and imports
    per_house = {}
    for n in numbers:
        seconds, tris = build(n)
        per_house[str(n)] = {"build_s": round(seconds, 3), "triangles": tris}

    empty_s, _ = _timed(_bare_client)
    with tempfile.TemporaryDirectory() as tmp:
        old = os.environ.get("RAVH_CACHE")
        os.environ["RAVH_CACHE"] = tmp
        try:
            cold_s, _ = build(15 if 15 in numbers else numbers[0])
        finally:
            if old is None:
                del os.environ["RAVH_CACHE"]
            else:
                os.environ["RAVH_CACHE"] = old
    times = [v["build_s"] for v in per_house.values()]
    warm15 = per_house.get("15", next(iter(per_house.values())))["build_s"]
    return {
        "houses": per_house,
        "build_s_max": max(times), "build_s_median": round(statistics.median(times), 3),
        "build_s_target": LOAD_TARGET_S, "max_over_target": round(max(times) / LOAD_TARGET_S, 3),
        "bare_client_s": round(empty_s, 3),
        "cold_cache_build_s_house15": round(cold_s, 3),
        "cold_over_warm_house15": round(cold_s / warm15, 2),
        "triangles_house23": per_house.get("23", {}).get("triangles"),
        "triangles_target_house23": TRIANGLE_TARGET_HOUSE23,
    }


def _bare_client() -> None:
    import pkgutil

    import pybullet as pb
    client = pb.connect(pb.DIRECT)
    loader = pkgutil.get_loader("eglRenderer")
    if loader is not None:
        pb.loadPlugin(loader.get_filename(), "_eglRendererPlugin", physicsClientId=client)
    pb.disconnect(client)
