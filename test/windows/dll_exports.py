"""Does j288.dll export every function the Python package binds (python/j288/_native.py)?

usage: python3 test/windows/dll_exports.py J288_DLL OBJDUMP
The names come from _native._bind's table (read with ast: nothing is loaded), the exports from
the DLL's export table (OBJDUMP -p). Prints the missing names and exits 1 when any is.
"""

import ast
import re
import subprocess
import sys
from pathlib import Path

NATIVE = Path(__file__).resolve().parents[2] / "python" / "j288" / "_native.py"


def bound_names() -> list:
    for node in ast.walk(ast.parse(NATIVE.read_text())):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Dict) and any(
                isinstance(t, ast.Name) and t.id == "protos" for t in node.targets):
            return [k.value for k in node.value.keys]
    sys.exit(f"{NATIVE}: no protos table found")


def exports(dll: str, objdump: str) -> set:
    text = subprocess.run([objdump, "-p", dll], check=True, capture_output=True, text=True).stdout
    table = text.split("[Ordinal/Name Pointer] Table", 1)[-1]
    return set(re.findall(r"^\s*\[\s*\d+\]\s+(\S+)", table, re.M))


def main() -> int:
    names = bound_names()
    missing = [n for n in names if n not in exports(sys.argv[1], sys.argv[2])]
    if missing:
        print(f"{sys.argv[1]} lacks {len(missing)} of the {len(names)} functions the Python "
              f"package binds: {' '.join(missing)}")
        return 1
    print(f"{sys.argv[1]} exports all {len(names)} functions the Python package binds")
    return 0


if __name__ == "__main__":
    sys.exit(main())
