"""Writing output files so that nothing half-written is ever left behind.

Every file goes to a temporary name in its own folder, is fsynced and renamed into place: a reader,
a full disk or a Ctrl-C at any instant leaves the old file or the new one, never a torn one. Images
are encoded in memory first, so a failed encoding writes nothing at all. Generated assets (meshes,
textures) go to a content-addressed cache the same way (:func:`cached_asset`).
"""
from __future__ import annotations

import hashlib
import os
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

TMP_PREFIX = "."                       # temporary files are hidden: ".<name>.<pid>.tmp"


def atomic_write(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` all at once: temp file in the same folder, fsync, rename.

    The fsync before the rename keeps the name from ever pointing at unwritten blocks after a
    power loss; os.replace is atomic on POSIX, so readers see the old file or the new one; a failed
    write removes its temp file.
    """
    tmp = path.with_name(f"{TMP_PREFIX}{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError as e:                  # full disk: no half-written file, and the error names the file
        tmp.unlink(missing_ok=True)
        raise named(e, path) from None
    except BaseException:                 # Ctrl-C: no half-written file stays behind
        tmp.unlink(missing_ok=True)
        raise


def named(error: OSError, path: Path | str) -> OSError:
    """``error`` naming ``path``: a failed write() or fsync() (a full disk) says no file of its own, and
    one on a temporary file should name the file it was for."""
    if error.filename is not None and not Path(error.filename).name.startswith(TMP_PREFIX):
        return error
    named_error = OSError(error.errno, error.strerror or str(error), str(path))
    named_error.__traceback__ = error.__traceback__
    return named_error


def write_image(path: Path, image: np.ndarray) -> None:
    """An image file in the format of ``path``'s suffix (cv2 channel order), written atomically."""
    ok, data = cv2.imencode(path.suffix, image)
    if not ok:
        raise OSError(f"cannot encode an image as {path.suffix!r}", str(path))
    atomic_write(path, data.tobytes())


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of an 8-bit RGB (H, W, 3) or a 16-bit (H, W) image."""
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_RGB2BGR)
    ok, buf = cv2.imencode(".png", image, [cv2.IMWRITE_PNG_COMPRESSION, 1])
    if not ok:
        raise ValueError(f"cannot encode a {image.dtype} {image.shape} image as PNG")
    return buf.tobytes()


def read_png(path: Path) -> np.ndarray:
    """The pixels of a PNG as written by :func:`encode_png` (RGB order for colour images)."""
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise OSError(f"{path}: cannot read the PNG")
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB) if image.ndim == 3 else image


def cache_dir() -> Path:
    """Where generated meshes and textures go (content-addressed, safe to share between runs)."""
    root = os.environ.get("RAVH_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "ravh_sim")
    path = Path(root) / "assets"
    path.mkdir(parents=True, exist_ok=True)
    return path


def cached_asset(key: bytes, suffix: str, write: Callable[[Path], object]) -> Path:
    """A content-addressed file in the asset cache, written atomically if missing."""
    path = cache_dir() / (hashlib.sha1(key).hexdigest()[:20] + suffix)
    if not path.exists():
        tmp = path.with_name(f"{path.stem}.{os.getpid()}.tmp{suffix}")
        write(tmp)
        os.replace(tmp, path)
    return path
