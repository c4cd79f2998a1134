"""Builds the Python package diffpills with CMake: the extension diffpills._core is the CMake target
diffpills_python (python/CMakeLists.txt), assembled straight into setuptools' build folder."""

import os
import pathlib
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).parent.resolve()


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        package_root = pathlib.Path(self.get_ext_fullpath(ext.name)).parent.parent.resolve()
        build_dir = pathlib.Path(self.build_temp).resolve() / "cmake"
        configure = [
            "cmake",
            "-S", str(ROOT),
            "-B", str(build_dir),
            "-DCMAKE_BUILD_TYPE=Release",
            "-DDIFFPILLS_PYTHON=ON",
            "-DDIFFPILLS_BUILD_TESTS=OFF",
            "-DDIFFPILLS_BUILD_BENCHMARKS=OFF",
            "-DDIFFPILLS_BUILD_APPS=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
            f"-DDIFFPILLS_PYTHON_OUTPUT_DIR={package_root}",
        ]
        subprocess.run(configure, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 2))
        subprocess.run(
            ["cmake", "--build", str(build_dir), "--target", "diffpills_python", "-j", jobs],
            check=True,
        )


setup(
    packages=["diffpills"],
    package_dir={"": "python"},
    package_data={"diffpills": ["*.pyi", "py.typed"]},
    ext_modules=[CMakeExtension("diffpills._core")],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    # setuptools' own folders under build/setuptools, apart from the CMake build trees in build*/.
    options={"build": {"build_base": "build/setuptools"}},
)
