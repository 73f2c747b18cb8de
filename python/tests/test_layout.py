"""Python's ctypes mirrors (j288/_native.py) against the C compiler's layout of the structs.

A program generated from the mirrors' own field lists, compiled against the headers next to
these tests ($CC, default cc; with $J288_CFLAGS when the build passes them), prints the size of
each mirrored C type and the offset, size and kind (signed, unsigned, bool, float, double,
other) of each mirrored field; every one must equal ctypes'. A field added, removed, moved or
retyped in C then fails here, not on a robot. Also: every Structure in _native names the C type
it mirrors, and the library loaded holds a j288_robot_t of the size these headers give (it was
built from them). The limit: a field added into a struct's trailing padding changes no size or
offset, and goes unseen (what Python reads stays right).
"""

from __future__ import annotations

import ctypes
import os
import shlex
import shutil
import subprocess
from pathlib import Path
from typing import Dict, List, Tuple, Type

import pytest

from j288 import _native

ROOT = Path(__file__).resolve().parents[2]
INCLUDES = ["lib/include", "port/desktop", "port/windows" if os.name == "nt" else "port/linux",
            "host"]

# C's kinds by _Generic (the probe is C11 for it; the headers are C99 and compile as C11).
KIND_MACRO = r"""
#define KIND(x) _Generic((x), _Bool: 'b', float: 'f', double: 'd', long double: 'D', \
    char: 'c', signed char: 's', short: 's', int: 's', long: 's', long long: 's', \
    unsigned char: 'u', unsigned short: 'u', unsigned int: 'u', unsigned long: 'u', \
    unsigned long long: 'u', default: 'o')
"""

# ctypes' simple type codes to the same kinds.
PY_KINDS = {"?": "b", "f": "f", "d": "d", "g": "D", "c": "c", "b": "s", "h": "s", "i": "s",
            "l": "s", "q": "s", "B": "u", "H": "u", "I": "u", "L": "u", "Q": "u"}


def mirrors() -> List[Type[ctypes.Structure]]:
    return [v for v in vars(_native).values()
            if isinstance(v, type) and issubclass(v, ctypes.Structure)
            and v.__module__ == _native.__name__]


def py_kind(t: type) -> str:
    code = getattr(t, "_type_", None)  # a class for pointers and structures: "o"
    return PY_KINDS.get(code, "o") if isinstance(code, str) else "o"


def probe_source(structs: List[Type[ctypes.Structure]]) -> str:
    out = ["#include <stddef.h>", "#include <stdio.h>", '#include "j288_robot.h"', KIND_MACRO,
           "int main(void)", "{",
           '    printf("j288_robot_t %zu\\n", sizeof(j288_robot_t));']
    for cls in structs:
        t = cls._c_type_  # type: ignore[attr-defined]
        out.append(f'    printf("{t} %zu\\n", sizeof({t}));')
        for name, _ in cls._fields_:
            m = f"(({t} *)0)->{name}"
            out.append(f'    printf("{t}.{name} %zu %zu %c\\n", offsetof({t}, {name}), '
                       f"sizeof({m}), KIND({m}));")
    out += ["    return 0;", "}", ""]
    return "\n".join(out)


def c_layout(tmp: Path, structs: List[Type[ctypes.Structure]]) -> Dict[str, Tuple[str, ...]]:
    """What the C compiler says, by "type" and "type.field"."""
    cc = os.environ.get("CC") or "cc"
    if shutil.which(cc.split()[0]) is None or not (ROOT / "host" / "j288_robot.h").exists():
        why = f"no C compiler ({cc})" if shutil.which(cc.split()[0]) is None else \
            f"no headers under {ROOT}"
        if os.environ.get("CI") == "true":
            pytest.fail(f"layout check impossible: {why} (CI=true)")
        pytest.skip(f"layout check skipped: {why}")
    src, exe = tmp / "layout_probe.c", tmp / "layout_probe"
    src.write_text(probe_source(structs))
    flags = shlex.split(os.environ.get("J288_CFLAGS", "")) + ["-std=c11"]
    cmd = [*shlex.split(cc), *flags, *[f"-I{ROOT / i}" for i in INCLUDES], str(src), "-o",
           str(exe)]
    built = subprocess.run(cmd, capture_output=True, text=True)
    assert built.returncode == 0, f"{' '.join(cmd)}\n{built.stderr}"
    ran = subprocess.run([str(exe)], capture_output=True, text=True, check=True)
    return {line.split()[0]: tuple(line.split()[1:]) for line in ran.stdout.splitlines()}


def test_every_mirror_names_its_c_type() -> None:
    unnamed = [cls.__name__ for cls in mirrors() if not getattr(cls, "_c_type_", "")]
    assert not unnamed, f"Structures without _c_type_ (unchecked against C): {unnamed}"


def test_mirrors_match_the_c_layout(tmp_path: Path) -> None:
    structs = mirrors()
    c = c_layout(tmp_path, structs)
    diffs = []
    for cls in structs:
        t = cls._c_type_  # type: ignore[attr-defined]
        if int(c[t][0]) != ctypes.sizeof(cls):
            diffs.append(f"{t}: size C {c[t][0]}, Python {ctypes.sizeof(cls)}")
        for name, ftype in cls._fields_:
            off, size, kind = c[f"{t}.{name}"]
            field = getattr(cls, name)
            py = (field.offset, field.size, py_kind(ftype))
            if (int(off), int(size), kind) != py:
                diffs.append(f"{t}.{name}: offset/size/kind C {off}/{size}/{kind}, "
                             f"Python {py[0]}/{py[1]}/{py[2]}")
    assert not diffs, "ctypes mirrors differ from C:\n  " + "\n  ".join(diffs)


def test_the_library_was_built_from_these_headers(tmp_path: Path) -> None:
    c = c_layout(tmp_path, [])
    assert int(c["j288_robot_t"][0]) == _native.LIB.j288_robot_sizeof()
