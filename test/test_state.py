"""One world state with one writer: frozen settings in, a live state that Appearance alone writes,
revisions that tell readers what changed, and a footprint that follows the state."""
from __future__ import annotations

import re
from pathlib import Path

import pytest
from conftest import ROOT, resolved
from pydantic import ValidationError

from ravh_sim.world.footprint import make_footprint
from ravh_sim.world.ground_truth import GroundTruth
from ravh_sim.world.scene import World
from ravh_sim.world.settings import Resolved
from ravh_sim.world.state import WorldState


def _revisions(world: World) -> tuple[int, int]:
    return world.state.revision, world.state.layout_revision


# ------------------------------------------------------------------ frozen settings

def test_resolved_settings_cannot_be_changed(houses):
    settings = resolved(houses[15])
    door = next(iter(settings.doors))
    with pytest.raises(ValidationError):                      # frozen
        settings.sun_angle = 3.0
    with pytest.raises(TypeError):
        settings.doors[door] = not settings.doors[door]
    with pytest.raises(TypeError):
        settings.paint["Bedroom_1"]["walls"] = "brick"
    with pytest.raises(AttributeError):
        settings.agents.append(settings.agents[0])


def test_resolved_keeps_its_own_copy_and_round_trips():
    doors = {"Door_0": True}
    settings = Resolved(seed=1, sun_angle=90.0, lights={}, doors=doors, paint={"A": {"walls": "white"}},
                        models={})
    doors["Door_0"] = False                                   # the caller's dict is not the record
    assert settings.doors["Door_0"] is True
    assert Resolved.model_validate(settings.model_dump(mode="json")) == settings
    closed = settings.changed(doors={"Door_0": False})
    assert closed.doors["Door_0"] is False and settings.doors["Door_0"] is True


# ------------------------------------------------------------------ the live state

def test_the_state_is_read_only_for_readers(world):
    door = next(iter(world.state.doors))
    with pytest.raises(TypeError):
        world.state.doors[door] = False
    with pytest.raises(TypeError):
        world.state.paint["Bedroom_1"]["walls"] = "brick"
    with pytest.raises(AttributeError):
        world.state.revision = 99


def test_writing_an_item_the_world_lacks_is_refused(houses):
    state = WorldState(resolved(houses[15]))
    with pytest.raises(KeyError, match="Door_99"):
        state.write(doors={"Door_99": False})
    with pytest.raises(KeyError, match="Attic"):
        state.write(paint={"Attic": {"walls": "brick"}})
    assert state.revision == 0


def test_every_appearance_change_bumps_the_revision_and_only_layout_the_layout_revision(world, appearance):
    door = world.house.doors[0].id
    light = world.house.lights[0].id
    changes = [  # (change, does it move doors or models?)
        (lambda: appearance.set_knob("sun_angle", 33.0), False),
        (lambda: appearance.set_light(light, not world.state.lights[light]), False),
        (lambda: appearance.set_lights("all", "off"), False),
        (lambda: appearance.set_paint("Bedroom_1", "walls", "brick"), False),
        (lambda: appearance.set_door(door, not world.state.doors[door]), True),
        (lambda: appearance.set_object_model("Bed_0", (world.state.models["Bed_0"] + 1) % 3), True),
        (lambda: appearance.change({"paint": {"all": {"floor": "white"}}}), False),
        (lambda: appearance.change({"doors": {door: not world.state.doors[door]}}), True),
    ]
    for change, layout in changes:
        revision, layout_revision = _revisions(world)
        change()
        assert world.state.revision > revision
        assert (world.state.layout_revision > layout_revision) is layout
        assert world.state.layout_revision >= layout_revision


def test_a_change_to_what_already_is_changes_no_revision(world, appearance):
    door = world.house.doors[0].id
    before = _revisions(world)
    appearance.set_knob("sun_angle", world.state.sun_angle)
    appearance.set_door(door, world.state.doors[door])
    appearance.apply(world.state.settings())
    assert _revisions(world) == before


def test_readers_are_told_which_fields_changed(world, appearance):
    """What the GL renderer redraws by: the fields whose revision moved since it last looked."""
    light = world.house.lights[0].id
    seen = world.state.revisions()
    appearance.set_knob("sun_angle", 33.0)
    appearance.set_light(light, not world.state.lights[light])
    assert world.state.changed_since(seen) == {"sun_angle", "lights"}
    appearance.set_paint("Bedroom_1", "walls", "brick")
    assert world.state.changed_since(seen) == {"sun_angle", "lights", "paint"}
    assert world.state.changed_since(world.state.revisions()) == frozenset()
    assert world.state.changed_since(None) == set(world.state.revisions())


def test_the_footprint_follows_the_live_state(world, appearance):
    door = world.house.doors[0].id
    start = world.state.settings()
    appearance.change({"doors": {door: "closed"}, "models": {"Bed_0": 2}, "sun_angle": "night"})
    now = make_footprint(world.house, world.state.settings())
    rows = {row["name"]: row for row in now["instances"]}
    assert rows[door]["open"] is False and rows["Bed_0"]["model"] == 2
    assert now["settings"]["sun_angle"] == 200.0 and now["settings"]["doors"][door] is False
    assert start.doors[door] is not False or start.models["Bed_0"] != 2     # it did change
    assert start == resolved(world.house)                                     # and the snapshot did not


def test_ground_truth_reads_the_live_state(world, appearance):
    door = world.house.doors[0].id
    truth = GroundTruth(world.house, world.state)
    appearance.set_door(door, False)
    assert truth.answer({"query": "door", "id": door})["result"]["open"] is False
    appearance.set_door(door, True)
    assert truth.answer({"query": "door", "id": door})["result"]["open"] is True


def test_only_appearance_writes_the_appearance_state():
    """One writer: outside the state module, only Appearance (and the Simulation, for the agents'
    real start poses) calls ``state.write``."""
    writers = {str(path.relative_to(ROOT)) for path in Path(ROOT, "ravh_sim").rglob("*.py")
               if re.search(r"state\.write\(", path.read_text())}
    assert writers == {"ravh_sim/world/appearance.py", "ravh_sim/robot/simulation.py"}
    simulation = Path(ROOT, "ravh_sim/robot/simulation.py").read_text()
    assert re.findall(r"state\.write\((\w+)=", simulation) == ["agents"]
