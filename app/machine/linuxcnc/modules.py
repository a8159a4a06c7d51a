"""Finding Debian's ``linuxcnc`` and ``hal`` python modules from any environment.

Debian's ``linuxcnc-uspace`` installs them for its own CPython (``linuxcnc.cpython-311-...so``,
``_hal...so``, ``hal.py`` under ``/usr/lib/python3/dist-packages``), which a virtual
environment does not see. Nothing is copied into the environment and the whole Debian
dist-packages folder is not put on ``sys.path`` (it would bring Debian's numpy & co. along):
the three files are loaded by path, once, and registered as ``linuxcnc``, ``_hal`` and
``hal``. An extension built for another CPython than the running one is refused with a
message that says so. ``LINUXCNC_PYTHON_DIR`` names another folder to look in first.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import os
import sys
import sysconfig
from pathlib import Path
from types import ModuleType

FOLDERS = ("/usr/lib/python3/dist-packages", f"/usr/lib/python3.{sys.version_info.minor}/dist-packages")
INSTALL_HINT = "install it with: apt-get install linuxcnc-uspace linuxcnc-uspace-dev"


class LinuxCncMissing(RuntimeError):
    """LinuxCNC (or its python module for this interpreter) is not installed."""


def _folders() -> list[Path]:
    given = os.environ.get("LINUXCNC_PYTHON_DIR")
    return [Path(p) for p in ((given,) if given else ()) + FOLDERS]


def _extension(folder: Path, name: str) -> Path | None:
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    exact = folder / f"{name}{suffix}"
    if exact.is_file():
        return exact
    return None


def _load(name: str, path: Path) -> ModuleType:
    if path.suffix == ".py":
        spec = importlib.util.spec_from_file_location(name, path)
    else:
        spec = importlib.util.spec_from_file_location(
            name, path, loader=importlib.machinery.ExtensionFileLoader(name, str(path)))
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load {name} from {path}", name=name, path=str(path))
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def locate() -> Path:
    """The folder holding ``linuxcnc`` and ``_hal`` built for this interpreter."""
    seen = []
    for folder in _folders():
        if _extension(folder, "linuxcnc") and _extension(folder, "_hal") and (folder / "hal.py").is_file():
            return folder
        seen += [p.name for p in folder.glob("linuxcnc.cpython-*.so")] if folder.is_dir() else []
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    if seen:
        raise LinuxCncMissing(f"LinuxCNC's python module is built for another Python ({', '.join(sorted(set(seen)))}); "
                              f"this interpreter is CPython {version}")
    raise LinuxCncMissing(f"LinuxCNC's python module is not installed; {INSTALL_HINT}")


def import_linuxcnc() -> tuple[ModuleType, ModuleType]:
    """``(linuxcnc, hal)``: imported normally where they are importable, else loaded by path."""
    if "linuxcnc" in sys.modules and "hal" in sys.modules:
        return sys.modules["linuxcnc"], sys.modules["hal"]
    try:
        import hal  # noqa: PLC0415
        import linuxcnc  # noqa: PLC0415
        return linuxcnc, hal
    except ImportError:
        pass
    folder = locate()
    linuxcnc_so, hal_so = _extension(folder, "linuxcnc"), _extension(folder, "_hal")
    assert linuxcnc_so is not None and hal_so is not None  # locate() returns a folder holding both
    linuxcnc = sys.modules.get("linuxcnc") or _load("linuxcnc", linuxcnc_so)
    if "_hal" not in sys.modules:
        _load("_hal", hal_so)
    hal = sys.modules.get("hal") or _load("hal", folder / "hal.py")
    return linuxcnc, hal


def available() -> bool:
    """LinuxCNC, its python module for this interpreter and ``halcompile`` are installed."""
    from shutil import which  # noqa: PLC0415

    try:
        locate()
    except LinuxCncMissing:
        return False
    return which("linuxcnc") is not None and which("halcompile") is not None
