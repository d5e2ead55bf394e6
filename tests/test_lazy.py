"""Every subpackage's exports resolve, and a submodule never shadows the lazy loader."""

from __future__ import annotations

import importlib
import pkgutil

import pytest

PACKAGES = ("analysis", "campaign", "control", "fem", "identification", "materials",
            "surrogates", "transfer")  # fmt: skip


@pytest.mark.parametrize("name", PACKAGES)
def test_every_export_resolves_after_its_submodules_are_imported(name):
    package = importlib.import_module(f"softbend.{name}")
    # Import every submodule first: one called like the loader (softbend.fem.export) must
    # not replace it.
    for module in pkgutil.iter_modules(package.__path__, f"{package.__name__}."):
        importlib.import_module(module.name)
    for export in package.__all__:
        assert getattr(package, export) is not None, export
    assert sorted(dir(package)) == sorted(package.__all__)
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        package.no_such_name  # noqa: B018
