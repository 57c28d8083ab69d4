"""Builds sfcsampler._core with the repository's CMake, for pip and python3 -m build.

Where the extension comes from, first match wins:
  SFCSAMPLER_PREBUILT=DIR          copy DIR/sfcsampler/_core*.so, DIR/sfcsampler/v1 and the
                                   kind modules DIR/sfcsampler/libsfcsampler-*.so
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
        """DIR with DIR/sfcsampler/_core*.so and DIR/sfcsampler/v1, built if needed."""
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
        cores = glob.glob(os.path.join(package, "_core*.so"))
        if len(cores) != 1:
            raise RuntimeError(f"expected one _core*.so in {package}, found {cores}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(cores[0], target)
        os.chmod(target, 0o755)
        # Kinds built as modules (libsfcsampler-cad.so: CAD models), which
        # _core loads from its own folder when a request first needs them.
        for module in glob.glob(os.path.join(package, "libsfcsampler-*.so")):
            copy = os.path.join(os.path.dirname(target), os.path.basename(module))
            shutil.copyfile(module, copy)
            os.chmod(copy, 0o755)
        # The gRPC stubs generated from proto/ at build time: sfcsampler.v1.
        v1 = os.path.join(os.path.dirname(target), "v1")
        os.makedirs(v1, exist_ok=True)
        for name in ("__init__.py", "sampler_pb2.py", "sampler_pb2_grpc.py"):
            shutil.copyfile(os.path.join(package, "v1", name), os.path.join(v1, name))


setup(packages=["sfcsampler"], ext_modules=[CMakeExtension("sfcsampler._core")],
      cmdclass={"build_ext": CMakeBuild})
