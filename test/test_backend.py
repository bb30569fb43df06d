"""The renderer backend choice (issue 31: no silent failure): when OpenGL cannot start, ``auto`` falls
back to the TinyRenderer and says why, once, and the choice records the reason."""
from __future__ import annotations

import pytest

from ravh_sim.render import backend
from ravh_sim.render.backend import BackendChoice, choose_backend, resolve_backend

REASON = "libEGL.so.1: cannot open shared object file: No such file or directory"


@pytest.fixture()
def broken_gl(monkeypatch):
    """OpenGL that cannot start, in a process that has not tried yet (a real context of this process,
    if one was made, comes back afterwards: a second EGL context is never made)."""
    def no_egl():
        raise OSError(REASON)

    monkeypatch.setattr(backend, "_gl", None)
    monkeypatch.setattr(backend, "_fallback_logged", False)
    monkeypatch.setattr(backend, "_create_context", no_egl)


def test_a_gl_that_cannot_start_is_named_once_and_recorded(broken_gl, caplog):
    with caplog.at_level("WARNING", logger=backend.__name__):
        first = choose_backend("auto")
        assert resolve_backend("auto") == "tiny"
        again = choose_backend("auto")
    assert first == again == BackendChoice("tiny", f"OSError: {REASON}")
    logged = [r for r in caplog.records if r.name == backend.__name__]
    assert len(logged) == 1 and logged[0].levelname == "WARNING"            # once, however often asked
    assert f"OSError: {REASON}" in logged[0].getMessage() and "TinyRenderer" in logged[0].getMessage()
    assert backend.gl_context() is None and backend.gl_start().failure == f"OSError: {REASON}"


def test_gl_asked_for_by_name_fails_with_the_reason(broken_gl):
    with pytest.raises(RuntimeError, match=f"could not be made: OSError: {REASON}"):
        choose_backend("gl")


def test_tiny_and_unknown_names_do_not_start_gl(broken_gl):
    assert choose_backend("tiny") == BackendChoice("tiny", None)
    assert backend._gl is None                                                # nothing was tried
    with pytest.raises(ValueError, match="renderer must be one of"):
        choose_backend("vulkan")
