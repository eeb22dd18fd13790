"""Builds fastcal's Python module with CMake for pip (pyproject.toml).

FASTCAL_BUILD_DIR: an existing CMake build tree of this source (scripts/build.sh's build/)
whose module is packed as it is, for this interpreter's Python version; otherwise the
module is built in a fresh tree under the build's temporary directory (a few minutes on
two cores). FASTCAL_CMAKE_ARGS: more arguments to that configure step.
"""

import glob
import os
import shlex
import shutil
import subprocess
import sys

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

ROOT = os.path.dirname(os.path.abspath(__file__))
# setuptools' own work goes out of CMake's build/ (scripts/build.sh's tree).
os.makedirs(os.path.join(ROOT, "build-pip"), exist_ok=True)


class BinaryDistribution(Distribution):
    """The wheel holds a compiled module: platform-specific."""

    def has_ext_modules(self):
        return True


class BuildWithCMake(build_py):
    def run(self):
        super().run()
        tree = os.environ.get("FASTCAL_BUILD_DIR")
        if not tree:
            tree = os.path.join(os.path.abspath(self.build_lib), "..", "fastcal-cmake")
            configure = [
                "cmake", "-S", ROOT, "-B", tree, "-DCMAKE_BUILD_TYPE=Release",
                f"-DPython3_EXECUTABLE={sys.executable}", "-DFASTCAL_BUILD_PYTHON=ON",
                "-DFASTCAL_BUILD_APPS=OFF", "-DFASTCAL_BUILD_TESTS=OFF",
                "-DFASTCAL_BUILD_BENCHMARKS=OFF", "-DFASTCAL_INSTALL=OFF",
            ] + shlex.split(os.environ.get("FASTCAL_CMAKE_ARGS", ""))
            subprocess.check_call(configure)
            jobs = str(os.cpu_count() or 2)
            subprocess.check_call(["cmake", "--build", tree, "--target", "fastcal_python",
                                   "-j", jobs])
        built = os.path.join(tree, "python", "fastcal")
        modules = glob.glob(os.path.join(built, "_fastcal*.so"))
        if not modules:
            sys.exit(f"fastcal: no compiled module in {built}: build the target fastcal_python "
                     "(scripts/build.sh) or leave FASTCAL_BUILD_DIR unset")
        target = os.path.join(self.build_lib, "fastcal")
        os.makedirs(target, exist_ok=True)
        for path in modules + [os.path.join(built, "_build.py")]:
            shutil.copy2(path, target)


setup(
    packages=["fastcal"],
    package_dir={"fastcal": "python/fastcal"},
    cmdclass={"build_py": BuildWithCMake},
    distclass=BinaryDistribution,
    options={"build": {"build_base": "build-pip"}, "egg_info": {"egg_base": "build-pip"}},
)
