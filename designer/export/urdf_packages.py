"""A URDF as MuJoCo can load it: `package://NAME/...` file names resolved against the folders the user
names for those packages (as ROS's package path would), relative file names against the URDF's folder.

ROS URDFs name their meshes `package://NAME/path`; MuJoCo knows no packages and reads that as a
relative path (`Error opening file 'package:/NAME/...'`). The resolved text is compiled from a string
with every file name absolute, so nothing is written beside the user's robot.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

from ..errors import DesignerError

#: a package URI's package name (what follows is the path inside that package)
PACKAGE_URI = re.compile(r"package://([^/\"'<>\s]+)/")
#: a file name attribute (meshes, textures) in URDF
_FILENAME = re.compile(r"""(\bfilename\s*=\s*)(["'])(.*?)\2""", re.S)


def packages_named(text: str) -> set[str]:
    """The package names a URDF's `package://` file names use."""
    return set(PACKAGE_URI.findall(text))


def check_package_paths(package_paths: Mapping[str, str | Path] | None) -> dict[str, Path]:
    """`package_paths` as {name: existing folder}.

    Raises:
        DesignerError: a folder that does not exist.
    """
    out = {}
    for name, folder in (package_paths or {}).items():
        if not Path(folder).is_dir():
            raise DesignerError(
                f"package_paths[{name!r}]={str(folder)!r} is not a folder",
                f"give the folder that package://{name}/ stands for",
            )
        out[name] = Path(folder).resolve()
    return out


def resolved_urdf(
    path: Path, package_paths: Mapping[str, str | Path] | None = None, text: str | None = None
) -> str:
    """The URDF at `path` (or its `text`, as if it lay at `path`) with every file name absolute:
    `package://NAME/rest` -> `<package_paths[NAME]>/rest`, a relative name -> from `path`'s folder;
    and MuJoCo told not to strip the folders (`<mujoco><compiler strippath="false"/>`) unless the URDF
    says otherwise in its own `<mujoco>` element.

    Raises:
        DesignerError: a package the URDF names and `package_paths` does not, or a missing folder.
    """
    text = path.read_text() if text is None else text
    folders = check_package_paths(package_paths)
    missing = sorted(packages_named(text) - folders.keys())
    if missing:
        name = missing[0]
        raise DesignerError(
            f"{path.name} names files by package://{', package://'.join(missing)}/..., which MuJoCo cannot "
            "resolve",
            f"give each package's folder, as ROS's package path would: package_paths={{{name!r}: 'DIR'}}",
        )

    def absolute(m: re.Match) -> str:
        name = m.group(3)
        uri = PACKAGE_URI.match(name)
        if uri:
            name = str(folders[uri.group(1)] / name[uri.end() :])
        elif not Path(name).is_absolute():
            name = str((path.parent / name).resolve())
        return f"{m.group(1)}{m.group(2)}{name}{m.group(2)}"

    text = _FILENAME.sub(absolute, text)
    if "<mujoco" not in text:
        text = re.sub(r"(<robot\b[^>]*>)", r'\1<mujoco><compiler strippath="false"/></mujoco>', text, count=1)
    return text


def mujoco_urdf(path: Path, package_paths: Mapping[str, str | Path] | None = None, text: str | None = None):
    """MuJoCo's compiled model of the URDF at `path` (or its `text`), its files resolved as
    `resolved_urdf` does.

    Raises:
        DesignerError: an unnamed package, or MuJoCo cannot load it (the reason in MuJoCo's words).
    """
    import mujoco

    resolved = resolved_urdf(path, package_paths, text)
    try:
        return mujoco.MjModel.from_xml_string(resolved)
    except ValueError as exc:
        raise DesignerError(
            f"MuJoCo cannot load {path.name}: {' '.join(str(exc).split())}",
            "fix the URDF or load it elsewhere",
        ) from None
