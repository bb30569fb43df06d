"""Switch off the pybullet EGL plugin's shadow-map pass, which costs most of a frame on a CPU GL.

The plugin's GL renderer draws the whole scene into a 4096x4096 shadow map before every image
(the global ``useShadowMap`` in GLInstancingRenderer.cpp, no API reaches it). On Mesa llvmpipe that
pass alone takes ~35 ms of a ~57 ms 640x480 frame, whatever the image size; a house's ceilings would
shadow every room anyway, so it adds nothing we want. The flag is a local symbol of the plugin
library: we find it in the library's ELF symbol table, find where the library is mapped in this
process, check that the byte is the expected ``true`` and write ``false``. Anything unexpected
(another build, a stripped library, no mapping) leaves the plugin untouched: images stay correct,
only slower.
"""
from __future__ import annotations

import ctypes
import os
import pkgutil
import struct
from functools import lru_cache

_SYMBOL = b"useShadowMap"
_SHT_SYMTAB = 2


def disable_shadow_map() -> bool:
    """Turn the shadow-map pass off for every EGL render in this process; True when it is off."""
    return _disable()


@lru_cache(maxsize=1)
def _disable() -> bool:
    loader = pkgutil.get_loader("eglRenderer")
    if loader is None:
        return False
    path = os.path.realpath(loader.get_filename())
    offset = _symbol_offset(path, _SYMBOL)
    base = _load_base(path)
    if offset is None or base is None or not _writable(path, base + offset):
        return False
    flag = ctypes.c_uint8.from_address(base + offset)
    if flag.value not in (0, 1):
        return False
    flag.value = 0
    return True


def _symbol_offset(path: str, name: bytes) -> int | None:
    """Value of a one-byte data symbol in a 64-bit little-endian ELF's ``.symtab`` (None if absent)."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError:
        return None
    if data[:6] != b"\x7fELF\x02\x01":
        return None
    (shoff,) = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", data, shoff + i * shentsize) for i in range(shnum)]
    for sec in sections:
        if sec[1] != _SHT_SYMTAB:
            continue
        strtab_offset = sections[sec[6]][4]
        offset, size, entsize = sec[4], sec[5], sec[9]
        for k in range(size // entsize):
            st_name, _, _, _, value, st_size = struct.unpack_from("<IBBHQQ", data, offset + k * entsize)
            start = strtab_offset + st_name
            if data[start:data.index(b"\0", start)] == name and st_size == 1:
                return value
    return None


def _mappings(path: str) -> list[tuple[int, int, str, int]]:
    """(start, end, permissions, file offset) of every mapping of ``path`` in this process."""
    rows = []
    with open("/proc/self/maps") as maps:
        for line in maps:
            parts = line.split(maxsplit=5)
            if len(parts) == 6 and os.path.realpath(parts[5].strip()) == path:
                start, end = (int(v, 16) for v in parts[0].split("-"))
                rows.append((start, end, parts[1], int(parts[2], 16)))
    return rows


def _load_base(path: str) -> int | None:
    return next((start for start, _, _, offset in _mappings(path) if offset == 0), None)


def _writable(path: str, address: int) -> bool:
    return any(start <= address < end and perms.startswith("rw") for start, end, perms, _ in _mappings(path))
