"""Command profiles for the CLI: a profile file, or a measured record whose commands are replayed."""

from __future__ import annotations

from pathlib import Path

RECORD_SUFFIXES = (".csv", ".txt", ".h5", ".hdf5")


def load_command_source(path):
    """:func:`taos.profiles.load_profile`, or for a measured record (``.csv``/``.h5``,
    :func:`taos.identify.data.load_test_data`) the profile replaying its commands
    (:func:`taos.profiles.profile_from_record`)."""
    from taos import profiles

    if Path(str(path)).suffix.lower() in RECORD_SUFFIXES:
        from taos.identify.data import load_test_data
        return profiles.profile_from_record(load_test_data(path))
    return profiles.load_profile(path)
