"""The loader's choice of shared library on each platform (no library is loaded here).

_find(platform, pkg) is given a folder holding the file of every platform: each platform must
pick its own (Linux libj288.so, Windows j288.dll, macOS libj288.dylib), and $J288_LIB wins
over all.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from j288 import _native

FILES = {"linux": "libj288.so", "win32": "j288.dll", "darwin": "libj288.dylib"}


@pytest.fixture
def pkg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.delenv("J288_LIB", raising=False)
    for name in FILES.values():
        (tmp_path / name).write_bytes(b"")
    return tmp_path


@pytest.mark.parametrize("platform", sorted(FILES))
def test_each_platform_picks_its_own_file(pkg: Path, platform: str) -> None:
    assert _native._find(platform, str(pkg)) == str(pkg / FILES[platform])


def test_other_unix_platforms_take_the_so(pkg: Path) -> None:
    assert _native._find("freebsd14", str(pkg)) == str(pkg / "libj288.so")


def test_j288_lib_wins(pkg: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("J288_LIB", "/elsewhere/j288.dll")
    assert _native._find("win32", str(pkg)) == "/elsewhere/j288.dll"


def test_windows_without_the_dll_says_which_file(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("J288_LIB", raising=False)
    monkeypatch.setattr(_native.ctypes.util, "find_library", lambda name: None)
    with pytest.raises(ImportError, match="j288.dll not found"):
        _native._find("win32", str(tmp_path))
