"""Where the package's bundled files (config/, urdf/) are, installed or in the source tree."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from grasp_torque_opt.core.exceptions import InputError

PACKAGE = "grasp_torque_opt"


def config_dirs() -> list[Path]:
    """Candidate config/ folders: installed shares (ROS prefixes, this Python), then the source."""
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    dirs = [Path(p) / "share" / PACKAGE / "config" for p in prefixes + [sys.prefix]]
    dirs.append(Path(__file__).resolve().parents[2] / "config")  # grasp_torque_opt/core/ -> root
    return [d for d in dirs if d.is_dir()]


def find_config(name: str, field: str = "scenario") -> Path:
    """A file given as a path, or by name among the bundled config files.

    Raises:
        InputError: naming ``field``, when neither exists.
    """
    path = Path(name).expanduser()
    if path.is_file():
        return path
    if not path.is_absolute():
        for d in config_dirs():
            if (d / path).is_file():
                return d / path
    raise InputError(field, f"file not found: {name} (nor in {', '.join(map(str, config_dirs()))})")
