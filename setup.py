"""`pip install .`: configures and builds the _bbm extension with the project's
CMake (tests and benchmarks off) for the interpreter pip runs, and installs the
package python/bbm with it."""

import os
import pathlib
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = ROOT / "build" / f"pip-{sys.implementation.cache_tag}"
        subprocess.check_call([
            "cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
            f"-DPython_EXECUTABLE={sys.executable}", "-DBBM_PYTHON=ON",
            "-DBBM_BUILD_TESTS=OFF", "-DBBM_BUILD_BENCH=OFF",
        ])
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        subprocess.check_call(["cmake", "--build", str(build), "--target", "bbm_python_package", "-j", jobs])
        target = pathlib.Path(self.get_ext_fullpath(ext.name)).parent
        target.mkdir(parents=True, exist_ok=True)
        for f in (build / "python" / "bbm").iterdir():
            shutil.copy2(f, target / f.name)


setup(
    packages=["bbm"],
    package_dir={"bbm": "python/bbm"},
    ext_modules=[Extension("bbm._bbm", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
)
