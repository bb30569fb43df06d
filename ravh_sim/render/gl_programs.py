"""The GL renderer's shaders and how Python talks to them: sources, the defines every shader shares
(the limits and codes both sides must agree on), uniform look-ups and matrix layout."""
from __future__ import annotations

from importlib import resources
from typing import TYPE_CHECKING

import numpy as np

from ravh_sim.look.materials import PATTERN

if TYPE_CHECKING:
    import moderngl

KINDS = {"floor": 0, "ceiling": 1, "walls": 2, "object": 3, "door": 4, "window": 5, "dressing": 6}
MAX_LIGHTS = 32                       # switched-on lights with a shadow map
MAX_ROOMS = 32                        # rooms of a house (the 30 houses have at most 14)
MAX_WINDOWS = 32                      # windows of a house (the 30 houses have at most 14)
WINDOW_SPAN = 64                      # a room's windows: first + WINDOW_SPAN * count (scene.frag)
LAMP_SHADOW_RANGE = 64.0              # m: a lamp's shadow map stores distance / this as its depth


def source(name: str) -> str:
    return (resources.files("ravh_sim.render") / "shaders" / name).read_text()


def header(pattern: int = -1) -> str:
    """The version line, the shared defines (``pattern``: the surface pattern a scene program draws)
    and common.glsl."""
    defines = [f"#define PATTERN_{name.upper()} {i}" for name, i in PATTERN.items()]
    defines.append(f"#define PATTERN_ID {pattern}")
    defines += [f"#define KIND_{name.upper()} {i}" for name, i in KINDS.items()]
    defines.append(f"#define MAX_LIGHTS {MAX_LIGHTS}")
    defines.append(f"#define MAX_ROOMS {MAX_ROOMS}")
    defines.append(f"#define MAX_WINDOWS {MAX_WINDOWS}")
    defines.append(f"#define WINDOW_SPAN {WINDOW_SPAN}")
    defines.append(f"#define LAMP_SHADOW_RANGE {LAMP_SHADOW_RANGE:.1f}")
    return "#version 430\n" + "\n".join(defines) + "\n" + source("common.glsl") + "\n"


def fullscreen_program(ctx: moderngl.Context, fragment: str) -> moderngl.Program:
    """A pass over every pixel: the full-screen triangle and ``fragment`` (a file in shaders/)."""
    return ctx.program(vertex_shader=header() + source("fullscreen.vert"),
                       fragment_shader=header() + source(fragment))


def uniform(program: moderngl.Program, name: str) -> moderngl.Uniform:
    """``program``'s uniform ``name`` (indexing a program finds its attributes and blocks too)."""
    import moderngl  # already loaded with the context (this module's import does not load it)
    member = program[name]
    if not isinstance(member, moderngl.Uniform):
        raise TypeError(f"{name} is not a uniform of the program")
    return member


def mat(m: np.ndarray) -> bytes:
    """A row-major numpy matrix as the column-major bytes GL wants."""
    return np.ascontiguousarray(m.T, dtype=np.float32).tobytes()
