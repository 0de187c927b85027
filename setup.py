"""Builds the fiblet Python module with CMake (the library and the pybind11
extension only) for `pip install .` / `pip wheel .`; pyproject.toml holds
the metadata. FIBLET_CMAKE_BUILD_DIR: reuse a configured build tree (the
test suite's, in CI) instead of configuring a fresh one."""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
WORK = ROOT / "build" / "python-wheel"  # setuptools' own files, inside the ignored build tree


def version():
    m = re.search(r"project\(fiblet VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    if not m:
        sys.exit("setup.py: no project version in CMakeLists.txt")
    return m.group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        given = os.environ.get("FIBLET_CMAKE_BUILD_DIR")
        build = Path(given) if given else WORK / "cmake"
        if not given:
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), *generator, "-DCMAKE_BUILD_TYPE=Release",
                            "-DFIBLET_BUILD_TESTS=OFF", "-DFIBLET_BUILD_BENCH=OFF", "-DFIBLET_BUILD_VIEWER=OFF",
                            "-DFIBLET_BUILD_PYTHON=ON", f"-DPython_EXECUTABLE={sys.executable}"], check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "fiblet_python", "-j", str(os.cpu_count() or 1)],
                       check=True)
        built = sorted((build / "python" / "fiblet").glob("_fiblet*.so"))
        if not built:
            sys.exit(f"setup.py: the build left no _fiblet module in {build / 'python' / 'fiblet'}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[0], target)


WORK.mkdir(parents=True, exist_ok=True)
setup(
    version=version(),
    packages=["fiblet"],
    package_dir={"fiblet": "python/fiblet"},
    ext_modules=[Extension("fiblet._fiblet", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": str(WORK)}, "egg_info": {"egg_base": str(WORK)}},
    zip_safe=False,
)
