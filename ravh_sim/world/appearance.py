"""Appearance managers: sun, lights, paint, object models and doors, changed at run time.

:class:`Appearance` is the one writer of a world's live state (``world.state``, see
:mod:`ravh_sim.world.state`): the CLI, the benchmarks, the gallery and the ROS appearance service
(:meth:`Appearance.change`, which speaks the request language of :mod:`ravh_msgs_py.appearance`) all
change a world through it, so the footprint always describes what the sensors see. Paint, models and
doors change pybullet bodies (through the World's primitives, no rebuild); the global knobs (the sun
angle, :data:`ravh_msgs_py.appearance.KNOBS`) and the lights are read by the camera at capture time, so
switching them costs nothing. Random choices go through
:func:`settings.resolve`, so "random" here picks exactly what the same seed picks in a settings file.
What the knobs mean for the light is the scene's light model's (:mod:`ravh_sim.look.lighting`).

A change that fails half-way is put back (:meth:`Appearance.apply`); should putting back fail too,
the world is neither as it was nor as asked, and that is never silent: :class:`RollbackError` names
what could not be put back, and it is logged as an error (this module's ``logging`` logger).
"""
from __future__ import annotations

import copy
import logging
from collections.abc import Callable, Mapping
from functools import lru_cache
from typing import Any

from ravh_msgs_py.appearance import DRESSING, KNOBS, LIGHT_GROUPS, SURFACES, SWITCH
from ravh_msgs_py.query import UNKNOWN_ID, QueryError
from ravh_sim.errors import UnknownNameError, UserError
from ravh_sim.world import paints
from ravh_sim.world.scene import World
from ravh_sim.world.settings import Resolved, fit_model, knob_value, light_group, load_settings, resolve
from ravh_sim.world.solids import model_count

RGB = tuple[float, float, float]
log = logging.getLogger(__name__)

class RollbackError(RuntimeError):
    """A change failed half-way and putting back what it had changed failed too: the world is neither as
    it was nor as asked. ``stuck`` names each item that could not be put back, with why; ``cause`` is
    the error that stopped the change."""

    def __init__(self, cause: BaseException, stuck: list[tuple[str, Exception]]) -> None:
        self.cause, self.stuck = cause, list(stuck)
        items = "; ".join(f"{item} ({type(e).__name__}: {e})" for item, e in self.stuck)
        super().__init__(f"an appearance change failed ({type(cause).__name__}: {cause}) and putting it back "
                         f"failed too, so the world is neither as it was nor as asked; not put back: {items}")


class Appearance:
    """Run-time changes to how a house looks: the only writer of ``world.state``'s appearance."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.house = world.house
        self.state = world.state
        self._bringing = False

    # ------------------------------------------------------------------ global knobs and lights
    def set_knob(self, name: str, choice: float | str, seed: int | None = None) -> None:
        """Set a global knob (KNOBS: "sun_angle", ...) to a number in its range or one of its words
        ("night"; "random" draws with ``seed``, by default the world's)."""
        self.state.write(**{name: knob_value(name, choice, self.state.seed if seed is None else seed)})

    def set_light(self, light_id: str, on: bool) -> None:
        if light_id not in self.house.light_by_id:
            raise UnknownNameError("light", light_id, list(self.house.light_by_id))
        self.state.write(lights={light_id: bool(on)})

    def set_lights(self, which: str = "all", state: str = "on", seed: int | None = None) -> None:
        """Switch a light group (all, ceiling, lamps) on, off or at random."""
        if which not in LIGHT_GROUPS:
            raise UnknownNameError("light group", which, list(LIGHT_GROUPS))
        if state not in SWITCH:
            raise UnknownNameError("light state", state, list(SWITCH))
        chosen = self._lights_named(which)
        states = self._resolve({"lights": {"set": {lid: state for lid in chosen}}}, seed).lights
        self.state.write(lights={lid: states[lid] for lid in chosen})

    # ------------------------------------------------------------------ bodies
    def set_paint(self, room_id: str, surface: str, paint: str) -> None:
        self.house.room(room_id)
        if surface not in SURFACES:
            raise UnknownNameError("surface", surface, list(SURFACES))
        if not paints.is_paint(paint):
            raise UnknownNameError("paint", paint, paints.all_paints() + ["#rrggbb"])
        self.world.repaint(room_id, surface, paint)
        self.state.write(paint={room_id: {surface: paint}})

    def set_object_model(self, object_id: str, model: int | str | dict[str, str],
                         seed: int | None = None) -> int:
        """Swap an object's model: an index, 'random' (seeded) or {'inherit': OTHER_ID}; returns it."""
        obj = self.house.object(object_id)
        if isinstance(model, bool) or not isinstance(model, (int, str, dict)):
            raise UserError(f"model must be an index, 'random' or {{'inherit': ID}}, got {model!r}")
        if isinstance(model, dict):
            if set(model) != {"inherit"}:
                raise UserError(f"model must be {{'inherit': OBJECT_ID}}, got {model!r}")
            index = self.state.models[self.house.object(model["inherit"]).id]
        elif model == "random":
            index = self._resolve({"models": {"set": {object_id: "random"}}}, seed).models[object_id]
        elif isinstance(model, int):
            index = model
        else:
            raise UserError(f"model must be an index, 'random' or {{'inherit': ID}}, got {model!r}")
        count = model_count(obj)
        if not 0 <= index < count:
            raise UserError(f"{object_id}: model index must be in 0..{count - 1}, got {index}")
        if index != self.state.models[object_id]:
            self.world.load_model(object_id, index)
            self.state.write(models={object_id: index})
            if not self._bringing:            # what stands on it moves with its new model
                self.set_dressing(self.state.dressing, force=True)
        return index

    def set_dressing(self, level: str, force: bool = False) -> None:
        """Show the dressing of ``level`` (none, tidy, lived-in), laid out for the objects' models now;
        ``force``: lay it out again even at the same level (an object model changed)."""
        if level not in DRESSING:
            raise UnknownNameError("dressing level", level, list(DRESSING))
        if level != self.state.dressing or force:
            self.world.dress(level, self.state.models)
            self.state.write(dressing=level)

    def set_door(self, door_id: str, is_open: bool) -> None:
        if door_id not in self.house.door_by_id:
            raise UnknownNameError("door", door_id, list(self.house.door_by_id))
        self.world.place_door(door_id, bool(is_open))
        self.state.write(doors={door_id: bool(is_open)})

    # ------------------------------------------------------------------ whole settings
    def apply(self, target: Resolved) -> None:
        """Bring the world to ``target`` (sun, lights, doors, paint, models), changing only what differs.

        All or nothing: every item of ``target`` is checked before anything moves, and should a change
        still fail half-way (pybullet, a full disk under the asset cache) the items already changed are
        put back, so the world, its state and its footprint are as they were before the call. Should
        putting an item back fail too, every other item is still put back, the error is logged and
        :class:`RollbackError` (naming what could not be put back) is raised from the first error."""
        self.check(target)
        before = self.state.settings()
        try:
            self._bring(target)
        except BaseException as error:
            stuck: list[tuple[str, Exception]] = []
            self._bring(before, stuck)
            if not stuck:
                raise
            failure = RollbackError(error, stuck)
            log.error("%s", failure)
            if not isinstance(error, Exception):      # an interrupt stays an interrupt (it was logged)
                raise
            raise failure from error

    def check(self, target: Resolved) -> None:
        """Refuse (UserError) a target this world cannot show: an unknown item, an unknown paint, a
        model index an object does not have (the model's own bounds, like the sun angle's range, held
        when ``target`` was made). Moves nothing."""
        house, state = self.house, self.state
        for kind, items, known in (("light", target.lights, state.lights), ("door", target.doors, state.doors),
                                   ("room", target.paint, state.paint), ("object", target.models, state.models)):
            for item in items:
                if item not in known:
                    raise UnknownNameError(kind, item, list(known))
        for room_id, surfaces in target.paint.items():
            for surface, paint in surfaces.items():
                if surface not in SURFACES:
                    raise UnknownNameError("surface", surface, list(SURFACES))
                if not paints.is_paint(paint):
                    raise UserError(f"{room_id}.{surface}: unknown paint {paint!r}")
        for object_id, index in target.models.items():
            count = model_count(house.object(object_id))
            if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < count:
                raise UserError(f"{object_id}: model index must be in 0..{count - 1}, got {index!r}")

    def randomise(self, seed: int) -> Resolved:
        """Random sun, lights, doors, paint and models (what a settings file of 'random' gives for
        ``seed``); returns the new settings. The noise seed and the agents stay as they were."""
        self.apply(self.randomised(seed))
        return self.state.settings()

    def randomised(self, seed: int) -> Resolved:
        """The settings :meth:`randomise` would bring, without changing anything."""
        return self._resolve({"lights": {"sun_angle": "random", "ceiling": "random", "lamps": "random"},
                              "doors": {"all": "random"},
                              "paint": {"walls": "random", "floors": "random"},
                              "models": {"all": "random"}}, seed)

    def change(self, request: dict[str, Any]) -> dict[str, Any]:
        """Apply a parsed appearance request (:func:`ravh_msgs_py.appearance.parse`) and return the
        reply's result. All or nothing: the whole request is checked against the house and every choice
        resolved like a settings file (same seed rules) before anything changes (:meth:`apply`); only
        the items the request names change."""
        if "randomise" in request:
            return {"settings": self.randomise(int(request["randomise"])).model_dump(mode="json")}
        self.apply(self.target(request))
        return {"settings": self.state.settings().model_dump(mode="json")}

    def target(self, request: dict[str, Any]) -> Resolved:
        """The settings a parsed appearance request asks for: the current ones with the items it names
        resolved; changes nothing. Unknown names and impossible values are refused here."""
        self.check_names(request)
        if "dressing" in request and request["dressing"] not in DRESSING:
            raise UserError(f"dressing: expected one of {', '.join(DRESSING)}, got {request['dressing']!r}")
        lights, doors, rooms, models = {}, {}, {}, {}
        inherit = {}
        for which, state in request.get("lights", {}).items():
            lights.update(dict.fromkeys(self._lights_named(which), state))
        for door, state in request.get("doors", {}).items():
            for d in self._named(door, self.house.door_by_id):
                doors[d] = {True: "open", False: "closed"}.get(state, state)
        for room, surfaces in request.get("paint", {}).items():
            rooms.update({r: dict(surfaces) for r in self._named(room, self.house.room_by_id)})
        for obj, model in request.get("models", {}).items():
            for o in self._named(obj, self.house.object_by_id):
                if isinstance(model, dict):
                    inherit[o] = self.house.object(model["inherit"]).id
                else:
                    models[o] = model
        overrides: dict[str, dict[str, Any]] = {"lights": {"set": lights}, "doors": {"set": doors},
                                                "paint": {"rooms": rooms}, "models": {"set": models}}
        knobs = [name for name in KNOBS if name in request]
        overrides["lights"].update({name: request[name] for name in knobs})
        picked = self._resolve(overrides, request.get("seed"), "appearance request")
        chosen_models = {o: picked.models[o] for o in models}
        for obj, source in inherit.items():
            chosen = chosen_models.get(source, self.state.models[source])
            chosen_models[obj] = fit_model(chosen, self.house.object(obj))
        now = self.state.settings()
        target = now.changed(
            **{name: getattr(picked, name) for name in knobs},
            lights={**now.lights, **{lid: picked.lights[lid] for lid in lights}},
            doors={**now.doors, **{d: picked.doors[d] for d in doors}},
            paint={r: {**s, **{k: picked.paint[r][k] for k in rooms.get(r, {})}} for r, s in now.paint.items()},
            models={**now.models, **chosen_models},
            dressing=request.get("dressing", now.dressing))
        self.check(target)
        return target

    def _bring(self, target: Resolved, stuck: list[tuple[str, Exception]] | None = None) -> None:
        """Change the items of ``target`` that differ, in the house's order (knobs, lights, doors, paint,
        models). The first failure raises; with ``stuck`` (putting a failed change back) every item is
        tried and each one that fails is added to ``stuck`` as (item, error) instead."""
        def change(item: str, act: Callable[..., object], *args: Any) -> None:
            if stuck is None:
                act(*args)
                return
            try:
                act(*args)
            except Exception as e:
                stuck.append((item, e))

        state = self.state
        models_before = dict(state.models)
        change("the global knobs", lambda: state.write(**{name: getattr(target, name) for name in KNOBS}))
        lights, doors, paint, models = target.lights, target.doors, target.paint, target.models
        for lid in list(state.lights):
            if lid in lights and lights[lid] != state.lights[lid]:
                change(f"light {lid}", self.set_light, lid, lights[lid])
        for did, is_open in list(state.doors.items()):
            if did in doors and doors[did] != is_open:
                change(f"door {did}", self.set_door, did, doors[did])
        for room_id, surfaces in list(state.paint.items()):
            for surface, paint_now in list(surfaces.items()):
                if surface in paint.get(room_id, {}) and paint[room_id][surface] != paint_now:
                    change(f"paint {room_id}.{surface}", self.set_paint, room_id, surface, paint[room_id][surface])
        self._bringing = True
        try:
            for oid, model in list(state.models.items()):
                if oid in models and models[oid] != model:
                    change(f"model of {oid} (index {models[oid]})", self.set_object_model, oid, models[oid])
        finally:
            self._bringing = False
        if target.dressing != state.dressing or dict(state.models) != models_before:
            change(f"dressing {target.dressing}", self.set_dressing, target.dressing, True)

    def _lights_named(self, which: str) -> list[str]:
        """The lights of a group (LIGHT_GROUPS) or the one light named ``which``."""
        if which in LIGHT_GROUPS:
            return [lt.id for lt in self.house.lights if which in ("all", light_group(lt))]
        return [which]

    @staticmethod
    def _named(name: str, known: Mapping[str, Any]) -> list[str]:
        return list(known) if name == "all" else [name]

    def check_names(self, request: dict[str, Any]) -> None:
        """Refuse (QueryError unknown_id) a parsed request that names a door, light, room or object the
        house lacks; cheap: nothing is resolved."""
        h = self.house
        for key, kind, known, groups in (("doors", "door", h.door_by_id, ("all",)),
                                         ("lights", "light", h.light_by_id, LIGHT_GROUPS),
                                         ("paint", "room", h.room_by_id, ("all",)),
                                         ("models", "object", h.object_by_id, ("all",))):
            for name in request.get(key, {}):
                if name not in groups and name not in known:
                    raise QueryError(UNKNOWN_ID, f"unknown {kind} {name!r}", [*groups, *known])

    def _resolve(self, overrides: dict[str, dict[str, Any]], seed: int | None,
                 source: str = "appearance") -> Resolved:
        """Resolve the default settings with ``overrides`` for this house (random picks by seed)."""
        cfg = _default_settings()
        for section, values in overrides.items():
            cfg[section] = {**cfg[section], **values}
        return resolve(cfg, self.house, self.state.seed if seed is None else seed, source)


@lru_cache(maxsize=1)
def _cached_defaults() -> dict[str, Any]:
    return load_settings()


def _default_settings() -> dict[str, Any]:
    return copy.deepcopy(_cached_defaults())

