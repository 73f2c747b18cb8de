"""The pip build's two steps pyproject.toml cannot say: the version, read from the one
J288_VERSION_STRING, and libj288.so, built from the C sources with `make shared` (a C compiler,
make; libyaml-dev for robot config files) and shipped inside the package, where the loader
(python/j288/_native.py) looks first after $J288_LIB. Shipping it makes a virtual environment
work without the library installed on the system; the wheel is therefore platform-specific.
"""

import os
import re
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(HERE, "lib", "include", "j288", "j288.h"), encoding="utf-8") as f:
        return re.search(r'#define J288_VERSION_STRING "([^"]+)"', f.read()).group(1)


class BuildWithLibrary(build_py):
    """build_py, then libj288.so into the built package."""

    def run(self):
        super().run()
        build = os.path.abspath(os.path.join(self.get_finalized_command("build").build_temp, "j288"))
        subprocess.check_call(["make", "-C", HERE, "BUILD=" + build, "shared"])
        dest = os.path.join(self.build_lib, "j288", "libj288.so")
        shutil.copyfile(os.path.realpath(os.path.join(build, "lib", "libj288.so")), dest)
        os.chmod(dest, 0o755)


class BinaryDistribution(Distribution):
    """A wheel for this platform: it holds a shared library."""

    def has_ext_modules(self):
        return True


setup(version=version(), cmdclass={"build_py": BuildWithLibrary}, distclass=BinaryDistribution)
