"""Our room type of a Sweet Home 3D room: from its name in the languages Sweet Home 3D ships, else from
what stands in it.

Why a table: people name rooms in their own language ("Chambre", "Küche", "Salón", "Bedrom #3"), and
room types drive ground truth, default paints and the paper's semantic evaluation. The rule:

1. a name containing one of :data:`NAME_WORDS`' words (accents and case ignored, first type listed wins)
   gives that type;
2. otherwise (no name, or an unknown one) the first of :data:`CONTENT_TYPES` whose object types stand in
   the room gives its type (a bed: Bedroom; a toilet, bath or shower: Bathroom...);
3. otherwise a room narrower than :data:`CORRIDOR_WIDTH` is a Corridor, anything else ``Standard``.
"""
from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable

# order matters: "Kitchen/living room" is KitchenLivingRoom before Kitchen; "bathroom" before "room"
NAME_WORDS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("KitchenLivingRoom", ("kitchen living", "kitchen/living", "living kitchen", "cuisine ouverte", "wohnkuche")),
    ("Bathroom", ("bath", "shower", "toilet", "wc", "washroom", "lavatory", "restroom", "salle de bain",
                  "salle d'eau", "bano", "aseo", "bad", "badezimmer", "bagno", "banheiro", "casa de banho",
                  "badkamer", "lazienka", "koupelna", "kylpyhuone", "badrum", "vannaya", "toilette")),
    ("Bedroom", ("bedroom", "bedrom", "bed room", "sleeping", "chambre", "dormitorio", "habitacion", "recamara",
                 "schlafzimmer", "kinderzimmer", "camera da letto", "camera", "quarto", "slaapkamer",
                 "sypialnia", "loznice", "makuuhuone", "sovrum", "spalnya", "nursery")),
    ("Kitchen", ("kitchen", "kitchenette", "cuisine", "cocina", "kuche", "kuchen", "cucina", "cozinha",
                 "keuken", "kuchnia", "kuchyne", "keittio", "kok", "kukhnya")),
    ("LivingRoom", ("living", "lounge", "sitting", "family room", "salon", "sejour", "sala",
                    "wohnzimmer", "wohnen", "soggiorno", "woonkamer", "salotto", "pokoj dzienny", "obyvak",
                    "olohuone", "vardagsrum", "gostinaya", "dining", "salle a manger", "comedor", "esszimmer")),
    ("Office", ("office", "study", "bureau", "despacho", "estudio", "oficina", "arbeitszimmer", "buro",
                "ufficio", "escritorio", "kantoor", "gabinet", "pracovna", "tyohuone", "kontor")),
    ("DressingRoom", ("dressing", "closet", "walk-in", "vestidor", "ankleide", "guardaroba")),
    ("UtilityRoom", ("utility", "laundry", "buanderie", "cellier", "lavadero", "waschkuche", "hauswirtschaft",
                     "lavanderia", "garage", "storage", "cellar", "cave", "keller", "attic", "grenier",
                     "dachboden", "boiler", "pantry")),
    ("Balcony", ("balcony", "balcon", "terrace", "terrasse", "terraza", "balkon", "balcone", "varanda",
                 "veranda", "patio", "loggia")),
    ("Hall", ("hall", "entrance", "entry", "foyer", "entree", "recibidor", "vestibulo", "diele", "eingang",
              "flur", "ingresso", "entrada", "hal", "przedpokoj", "predsin", "eteinen")),
    ("Corridor", ("corridor", "hallway", "passage", "couloir", "degagement", "pasillo", "gang", "corridoio",
                  "corredor", "korytarz", "chodba", "kaytava", "korridor", "landing", "stairs")),
)
CONTENT_TYPES: tuple[tuple[str, frozenset[str]], ...] = (
    ("Bathroom", frozenset({"Toilet", "Bathtub", "ShowerCabin", "Washbasin"})),
    ("Bedroom", frozenset({"Bed"})),
    ("Kitchen", frozenset({"Burner", "Oven", "Refrigerator", "Dishwasher", "Sink", "KitchenFurniture"})),
    ("LivingRoom", frozenset({"Sofa", "Tv", "Armchair"})),
    ("Office", frozenset({"Desk"})),
)
CORRIDOR_WIDTH = 1.6        # m: the narrow side of a room's bounding box below which it is a passage
FALLBACK = "Standard"


def plain(text: str) -> str:
    """Lower case without accents, so "Küche" meets "kuche" and "Séjour" meets "sejour"."""
    decomposed = unicodedata.normalize("NFKD", text.lower())
    return "".join(c for c in decomposed if not unicodedata.combining(c))


def type_from_name(name: str) -> str | None:
    """The room type a name says (rule 1), or None."""
    text = f" {plain(name)} "
    for room_type, words in NAME_WORDS:
        if any(re.search(rf"(?<![a-z]){re.escape(w)}", text) for w in words):
            return room_type
    return None


def room_type(name: str, object_types: Iterable[str], narrow_side: float) -> str:
    """The type of a room named ``name`` (may be empty) holding objects of ``object_types``."""
    named = type_from_name(name) if name else None
    if named:
        return named
    present = set(object_types)
    for content_type, types in CONTENT_TYPES:
        if present & types:
            return content_type
    return "Corridor" if narrow_side < CORRIDOR_WIDTH else FALLBACK
