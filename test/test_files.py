"""ravh_sim.files: a write that fails (a full disk, a file-size limit) leaves the old file and no temp file."""
from __future__ import annotations

import errno
import resource
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from ravh_sim import files


@contextmanager
def file_size_limit(limit: int) -> Iterator[None]:
    """Writes past ``limit`` bytes fail with EFBIG, as on a full disk (Python ignores SIGXFSZ); only
    the soft limit is lowered, so it can be raised back."""
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(files.TMP_PREFIX))


def test_a_write_past_the_space_left_keeps_the_old_file(tmp_path):
    path = tmp_path / "raid.json"
    files.atomic_write(path, b"old\n")
    with file_size_limit(4096), pytest.raises(OSError) as e:
        files.atomic_write(path, b"x" * 100_000)
    assert e.value.errno == errno.EFBIG
    assert path.read_bytes() == b"old\n" and leftovers(tmp_path) == []


def test_a_failed_fsync_keeps_the_old_file(tmp_path, monkeypatch):
    """Some file systems report a full disk only when the data is flushed."""
    path = tmp_path / "raid.json"
    files.atomic_write(path, b"old\n")

    def no_space(_fd: int) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files.os, "fsync", no_space)
    with pytest.raises(OSError, match="No space") as e:
        files.atomic_write(path, b"new\n")
    assert e.value.filename == str(path) and e.value.errno == errno.ENOSPC     # names the file (issue 24)
    assert f"No space left on device: '{path}'" in str(e.value)
    assert path.read_bytes() == b"old\n" and leftovers(tmp_path) == []
    with pytest.raises(OSError, match="No space"):
        files.atomic_write(tmp_path / "new.json", b"new\n")
    assert not (tmp_path / "new.json").exists() and leftovers(tmp_path) == []
