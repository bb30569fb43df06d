"""A ``.sh3d`` file opened as untrusted input: a bounded zip, a ``Home.xml`` without DTD, entries by name.

Why: ``ravh import-home`` reads files people download. A zip can lie about sizes or hold a bomb; an XML
file can declare entities that expand to gigabytes or read local files. So before anything is parsed:
the central directory is bounded (entries, sizes, compression ratio, names inside the archive), the XML
is refused if it declares a DOCTYPE or an entity (Sweet Home 3D never writes one; the stdlib parser
would otherwise expand internal entities), and every count the importer walks is bounded. Every
problem is one :class:`~ravh_sim.errors.FileFieldError` line naming the file and the entry or element.
"""
from __future__ import annotations

import re
import zipfile
from pathlib import Path, PurePosixPath
from xml.etree import ElementTree

from ravh_sim.errors import FileFieldError, UserError

MAX_ENTRIES = 4000
MAX_ENTRY_BYTES = 64 << 20          # one model or texture, uncompressed
MAX_TOTAL_BYTES = 512 << 20         # every entry, uncompressed
MAX_RATIO = 200                     # uncompressed / compressed of an entry over RATIO_FROM bytes
RATIO_FROM = 1 << 20
MAX_XML_BYTES = 32 << 20
MAX_ELEMENTS = 200_000              # elements of Home.xml
HOME_XML = "Home.xml"
_DECLARATION = re.compile(rb"<!\s*(DOCTYPE|ENTITY)", re.IGNORECASE)


class Sh3dArchive:
    """An open ``.sh3d``: :meth:`home` parses Home.xml, :meth:`read` gives an entry's bytes; the zip
    object (:attr:`zip`) is for readers that take one, after the bounds here were checked."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        try:
            self.zip = zipfile.ZipFile(self.path)
        except (OSError, zipfile.BadZipFile) as e:
            raise UserError(f"{path}: not a Sweet Home 3D file (.sh3d is a zip): {e}") from None
        self._check_directory()

    def __enter__(self) -> Sh3dArchive:
        return self

    def __exit__(self, *exc: object) -> None:
        self.zip.close()

    def _check_directory(self) -> None:
        infos = self.zip.infolist()
        if len(infos) > MAX_ENTRIES:
            raise FileFieldError(self.path, "(zip)", f"{len(infos)} entries, over the limit of {MAX_ENTRIES}")
        total = 0
        for info in infos:
            safe_name(self.path, info.filename)
            if info.file_size > MAX_ENTRY_BYTES:
                raise FileFieldError(self.path, info.filename, f"{info.file_size} bytes uncompressed, over the "
                                     f"limit of {MAX_ENTRY_BYTES >> 20} MiB")
            if info.file_size > RATIO_FROM and info.file_size > MAX_RATIO * max(info.compress_size, 1):
                ratio = info.file_size // max(info.compress_size, 1)
                raise FileFieldError(self.path, info.filename, f"compressed {ratio} to 1, over {MAX_RATIO} to 1: "
                                     "refused as a zip bomb")
            total += info.file_size
        if total > MAX_TOTAL_BYTES:
            raise FileFieldError(self.path, "(zip)", f"{total >> 20} MiB uncompressed, over the limit of "
                                 f"{MAX_TOTAL_BYTES >> 20} MiB")

    def names(self) -> set[str]:
        return set(self.zip.namelist())

    def read(self, name: str, element: str) -> bytes:
        """The bytes of entry ``name`` (named by ``element`` of Home.xml); a missing or unsafe name is
        one error line."""
        safe_name(self.path, name, element)
        if name not in self.names():
            raise FileFieldError(self.path, element, f"names entry {name!r}, which the archive lacks")
        with self.zip.open(name) as f:
            data = f.read(MAX_ENTRY_BYTES + 1)
        if len(data) > MAX_ENTRY_BYTES:                  # a directory that lied about the size
            raise FileFieldError(self.path, name, f"over the limit of {MAX_ENTRY_BYTES >> 20} MiB")
        return data

    def home(self) -> ElementTree.Element:
        """Home.xml's root ``<home>`` element, parsed only once it holds no DOCTYPE or entity declaration."""
        if HOME_XML not in self.names():
            raise FileFieldError(self.path, HOME_XML, "missing: saved by Sweet Home 3D older than 5.3? "
                                 "Open and save it again with a recent version")
        data = self.read(HOME_XML, HOME_XML)
        if len(data) > MAX_XML_BYTES:
            raise FileFieldError(self.path, HOME_XML, f"over the limit of {MAX_XML_BYTES >> 20} MiB")
        declared = _DECLARATION.search(data)
        if declared:
            raise FileFieldError(self.path, HOME_XML, f"declares a {declared[1].decode().upper()}: refused "
                                 "(no DTD or entity is ever expanded)")
        try:
            root = ElementTree.fromstring(data)
        except ElementTree.ParseError as e:
            raise FileFieldError(self.path, HOME_XML, f"not well-formed XML: {e}") from None
        if root.tag != "home":
            raise FileFieldError(self.path, HOME_XML, f"root element is <{root.tag[:40]}>, expected <home>")
        count = sum(1 for _ in root.iter())
        if count > MAX_ELEMENTS:
            raise FileFieldError(self.path, HOME_XML, f"{count} elements, over the limit of {MAX_ELEMENTS}")
        return root


def safe_name(archive: Path, name: str, element: str = "(zip)") -> str:
    """``name`` if it stays inside the archive (relative, no ``..``, no drive or backslash tricks)."""
    path = PurePosixPath(name)
    if not name or path.is_absolute() or ".." in path.parts or "\\" in name or ":" in name or "\x00" in name:
        raise FileFieldError(archive, element, f"entry name {name[:80]!r} points outside the archive: refused")
    return name
