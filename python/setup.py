"""Builds the pneumid extension module with CMake.

    pip install --no-build-isolation ./python          # from the repository root
    pip install --no-build-isolation .                 # from python/

The extension is the CMake target `pneumid_python` of the repository's
top-level CMakeLists.txt (python/CMakeLists.txt), configured for the
interpreter running this script. Environment variables:
    PNEUMID_CMAKE_ARGS   extra arguments for the CMake configure step
    PNEUMID_BUILD_JOBS   parallel build jobs (default 2)
"""
import os
import shlex
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
SOURCE_DIR = HERE.parent


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        out_dir = Path(self.get_ext_fullpath(ext.name)).resolve().parent
        out_dir.mkdir(parents=True, exist_ok=True)
        build_dir = Path(self.build_temp).resolve() / "cmake"
        build_dir.mkdir(parents=True, exist_ok=True)
        args = [
            "cmake", "-S", str(SOURCE_DIR), "-B", str(build_dir),
            "-DCMAKE_BUILD_TYPE=Release",
            "-DPNEUMID_BUILD_PYTHON=ON",
            "-DPNEUMID_BUILD_TESTS=OFF",
            "-DPNEUMID_BUILD_BENCHMARKS=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
            f"-DPNEUMID_PYTHON_OUTPUT_DIR={out_dir}",
        ]
        args += shlex.split(os.environ.get("PNEUMID_CMAKE_ARGS", ""))
        subprocess.run(args, check=True)
        jobs = os.environ.get("PNEUMID_BUILD_JOBS", "2")
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "pneumid_python",
                        "-j", jobs], check=True)


setup(
    ext_modules=[CMakeExtension("pneumid")],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
