"""Builds sfcsampler._core and sfcsampler._client with the repository's CMake, for pip
and python3 -m build.

Where the extensions come from, first match wins:
  SFCSAMPLER_PREBUILT=DIR          copy DIR/sfcsampler/_core*.so, DIR/sfcsampler/_client*.so
                                   and the kind modules DIR/sfcsampler/libsfcsampler-*.so
                                   (a configured build's python/ folder; no compiling)
  SFCSAMPLER_CMAKE_BUILD_DIR=DIR   build the target sfcsampler_python in that CMake build
  (neither)                        configure and build the repository in build/cmake
                                   beside this file (Release, no tests or benchmarks),
                                   with ccache when it is installed
SFCSAMPLER_BUILD_JOBS sets the parallel jobs (default 2).
"""

import glob
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.realpath(__file__))
ROOT = os.path.dirname(HERE)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def run(self):
        for ext in self.extensions:
            self.build_extension(ext)

    def _package_dir(self):
        """DIR with DIR/sfcsampler/_core*.so and _client*.so, built if needed."""
        prebuilt = os.environ.get("SFCSAMPLER_PREBUILT")
        if prebuilt:
            return os.path.abspath(prebuilt)
        build_dir = os.environ.get("SFCSAMPLER_CMAKE_BUILD_DIR")
        jobs = os.environ.get("SFCSAMPLER_BUILD_JOBS", "2")
        if not build_dir:
            build_dir = os.path.join(HERE, "build", "cmake")
            configure = ["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                         "-DSFC_BUILD_TESTS=OFF", "-DSFC_BUILD_BENCHMARKS=OFF",
                         f"-DPython_EXECUTABLE={sys.executable}"]
            if shutil.which("ninja"):
                configure += ["-G", "Ninja"]
            if shutil.which("ccache"):
                configure += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
            subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", build_dir, "--target", "sfcsampler_python", "-j", jobs],
                       check=True)
        return os.path.join(os.path.abspath(build_dir), "python")

    def build_extension(self, ext):
        package = os.path.join(self._package_dir(), "sfcsampler")
        stem = ext.name.rsplit(".", 1)[-1]
        built = glob.glob(os.path.join(package, stem + "*.so"))
        if len(built) != 1:
            raise RuntimeError(f"expected one {stem}*.so in {package}, found {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built[0], target)
        os.chmod(target, 0o755)
        # Kinds built as modules (libsfcsampler-cad.so: CAD models), which
        # _core loads from its own folder when a request first needs them.
        modules = glob.glob(os.path.join(package, "libsfcsampler-*.so")) if stem == "_core" else []
        for module in modules:
            copy = os.path.join(os.path.dirname(target), os.path.basename(module))
            shutil.copyfile(module, copy)
            os.chmod(copy, 0o755)


setup(packages=["sfcsampler"],
      ext_modules=[CMakeExtension("sfcsampler._core"), CMakeExtension("sfcsampler._client")],
      cmdclass={"build_ext": CMakeBuild})
