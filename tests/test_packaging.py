"""The installed layout: agents/ and experiments/ install inside the package, and every package
folder of the tree is in pyproject's explicit package list (a package-dir mapping cannot be
discovered, so a new folder left out of the list would be missing from a wheel)."""

from __future__ import annotations

from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parent.parent


def _setuptools() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]


def installed_packages() -> dict[str, Path]:
    """Dotted package name -> its folder, for every folder with an ``__init__.py`` under the
    package roots of pyproject's package-dir mapping (the package itself at ``encctl_gym/``)."""
    roots = {"encctl_gym": ROOT / "encctl_gym"} | {name: ROOT / folder for name, folder in _setuptools()["package-dir"].items()}
    found: dict[str, Path] = {}
    for name, folder in roots.items():
        for init in folder.rglob("__init__.py"):
            rel = init.parent.relative_to(folder).parts
            found[".".join((name, *rel))] = init.parent
    return found


def test_the_package_list_names_every_package_folder() -> None:
    listed = set(_setuptools()["packages"])
    on_disk = set(installed_packages())
    assert on_disk - listed == set(), "package folders missing from pyproject's [tool.setuptools] packages"
    assert listed - on_disk == set(), "pyproject lists packages with no folder"


def test_agents_and_experiments_install_inside_the_package() -> None:
    mapping = _setuptools()["package-dir"]
    assert mapping == {"encctl_gym.agents": "agents", "encctl_gym.experiments": "experiments"}
    tops = {name.split(".")[0] for name in _setuptools()["packages"]}
    assert tops == {"encctl_gym"}


def test_the_mapped_packages_import_from_their_folders() -> None:
    import encctl_gym.agents
    import encctl_gym.experiments

    assert Path(encctl_gym.agents.__file__).resolve().parent == ROOT / "agents"
    assert Path(encctl_gym.experiments.__file__).resolve().parent == ROOT / "experiments"
