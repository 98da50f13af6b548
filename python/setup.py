"""Build hook of the curvetet wheel: compiles the library with cargo and ships it.

`build_py` runs `cargo build --release --no-default-features` (the library alone, without
the command-line tool's crates) on the repository this directory belongs to (or
$CURVETET_SOURCE_DIR), honouring $CARGO_TARGET_DIR, and copies target/release/libcurvetet.so
into the package (debug info stripped when `strip` is there). The package calls the
library through ctypes, not the Python C API, so the wheel is tagged py3-none-<platform>:
platform-specific (it holds a native library) but for any Python 3, and installs with no
compiler.
"""

import os
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

try:
    from setuptools.command.bdist_wheel import bdist_wheel
except ImportError:  # setuptools < 70.1
    from wheel.bdist_wheel import bdist_wheel

HERE = os.path.dirname(os.path.abspath(__file__))


def _source_dir() -> str:
    src = os.environ.get("CURVETET_SOURCE_DIR") or os.path.dirname(HERE)
    if not os.path.exists(os.path.join(src, "Cargo.toml")):
        raise SystemExit(
            "curvetet: no Cargo.toml in %s: build the wheel from the repository's python/ "
            "directory, or set CURVETET_SOURCE_DIR to the repository" % src
        )
    return src


def _build_library() -> str:
    src = _source_dir()
    subprocess.run(
        ["cargo", "build", "--release", "--no-default-features", "--lib"], cwd=src, check=True
    )
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(src, "target")
    lib = os.path.join(target, "release", "libcurvetet.so")
    if not os.path.exists(lib):
        raise SystemExit("curvetet: cargo built no %s" % lib)
    return lib


class BuildPy(build_py):
    """build_py, then the shared library into the built package."""

    def run(self) -> None:
        super().run()
        dest = os.path.join(self.build_lib, "curvetet", "libcurvetet.so")
        shutil.copyfile(_build_library(), dest)
        os.chmod(dest, 0o755)
        strip = shutil.which("strip")
        if strip:
            subprocess.run([strip, "--strip-debug", dest], check=True)


class BinaryDistribution(Distribution):
    """Not a pure-Python distribution: it ships a native library."""

    def has_ext_modules(self) -> bool:
        return True


class BdistWheel(bdist_wheel):
    """Platform wheel for any Python 3 (ctypes, no Python C API): py3-none-<platform>."""

    def finalize_options(self) -> None:
        super().finalize_options()
        self.root_is_pure = False

    def get_tag(self):  # type: ignore[no-untyped-def]
        _, _, plat = super().get_tag()
        return "py3", "none", plat


setup(
    distclass=BinaryDistribution,
    cmdclass={"build_py": BuildPy, "bdist_wheel": BdistWheel},
)
