"""The build step of `pip install --no-build-isolation .` (pyproject.toml; docs/python.md):
CMake builds the module target dpc_python for the interpreter running pip (its headers, its
extension suffix), and setuptools packs the result.

The CMake tree is build-python-<tag>-<hash> beside the sources, one per base interpreter (a
venv shares its base's), kept so that a second install rebuilds only what changed. Settings:
CMAKE_BUILD_PARALLEL_LEVEL (compile jobs; default: every core), DPC_CMAKE_ARGS (more CMake
arguments, split on spaces).
"""
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def project_version():
    """The version of CMakeLists.txt's project(), the one definition of dpc's version."""
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(dpc VERSION ([0-9.]+)", text).group(1)


def cmake_tree():
    """The CMake build tree of this interpreter (of its base, when pip runs in a venv)."""
    base = os.path.realpath(getattr(sys, "_base_executable", sys.executable))
    digest = hashlib.sha256(base.encode()).hexdigest()[:8]
    return ROOT / f"build-python-{sys.implementation.cache_tag}-{digest}"


def configure(tree):
    args = ["cmake", "-S", str(ROOT), "-B", str(tree), "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
            f"-DDPC_PYTHON={sys.executable}", "-DDPC_BUILD_TESTS=OFF"]
    if not (tree / "CMakeCache.txt").exists():
        # What scripts/build.sh chooses: Ninja and ccache when installed.
        if shutil.which("ninja"):
            args += ["-G", "Ninja"]
        if shutil.which("ccache"):
            args += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
    args += os.environ.get("DPC_CMAKE_ARGS", "").split()
    subprocess.run(args, check=True)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        tree = TREE
        configure(tree)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", str(tree), "--target", "dpc_python", "-j", jobs],
                       check=True)
        # The file this interpreter imports: CMake's pybind11 must have named it the same.
        built = tree / "python" / ("dpc" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not built.is_file():
            found = sorted(p.name for p in (tree / "python").glob("dpc*.so"))
            sys.exit(f"setup.py: CMake built {found}, not {built.name} for {sys.executable}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, target)


TREE = cmake_tree()
TREE.mkdir(exist_ok=True)  # egg_info writes dpc.egg-info there before the build starts
setup(
    version=project_version(),
    ext_modules=[Extension("dpc", sources=[])],
    packages=[],  # the module is the extension alone: no automatic discovery of folders
    py_modules=[],
    cmdclass={"build_ext": CMakeBuild},
    # setuptools' own files go inside the CMake tree, not into ./build (scripts/build.sh's).
    options={"build": {"build_base": str(TREE / "setuptools")},
             "egg_info": {"egg_base": str(TREE)}},
    zip_safe=False,
)
