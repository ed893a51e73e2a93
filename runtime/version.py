"""The installed soccer-arena's version (the source tree's when it is not installed)."""

from __future__ import annotations


def package_version() -> str:
    from importlib import metadata

    try:
        return metadata.version("soccer-arena")
    except metadata.PackageNotFoundError:
        from arena import __version__

        return __version__
