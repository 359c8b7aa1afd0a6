"""One rule for every file named inside another file (issue 38.5, :func:`taos.shipped.resolve_reference`).

A reference is a path relative to the file that names it; it is looked for beside that file,
then as the same path from the shipped folder of that kind of file (``models/``,
``models/flight/``, ``models/montecarlo/``, ``models/masv/``), so a shipped file copied alone to
another folder still finds what it names; a file placed beside the copy wins; one in neither
place is bad input (exit 2), one line naming the referring file, the field and both places.
Every kind of reference below goes through the same three checks."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import pytest

from taos.errors import InputError
from taos.shipped import resolve_reference
from tests.conftest import MODELS, ROOT, run_cli


def _parameter_set(role):
    def get(p):
        from taos.model import load_model
        return load_model(p).input_files[role][0]
    return get


def _stiffness(p):
    from taos.model import load_model
    from taos.taos3d.model import assemble_taos_model

    model = load_model(p)
    used = assemble_taos_model(model).stiffness_source
    assert model.input_files["stiffness_file"][0] == used   # the provenance records the file read
    return used


def _flight_tvc(p):
    from taos.flight.vehicle import load_flight
    return load_flight(p).tvc_model


def _ascent(attr):
    def get(p):
        from taos.flight.ascent import load_ascent
        a = load_ascent(p)
        return a.flight.source if attr == "flight" else a.tvc_model
    return get


def _campaign(attr):
    def get(p):
        from taos.montecarlo.campaign import load_campaign
        c = load_campaign(p)
        return c.ascent_file if attr == "ascent" else c.tvc_model_file
    return get


def _masv(attr):
    def get(p):
        from masv.config import load_config
        c = load_config(p)
        return {"modes": c.structure.source, "model": c.engines[0].model.source, "reference": c.reference}[attr]
    return get


#: (referring shipped file under models/, field, reference as written, error field, what the
#: loaded file used, text added to the copy first)
CASES = {
    "actuator parameter set": ("rs25_hotfire.toml", "actuator.parameter_set", "actuators/tvc_actuator.toml",
                               "parameter_set", _parameter_set("actuator_parameter_set"), None),
    "friction parameter set": ("rs25_hotfire.toml", "friction.parameter_set", "friction/rs25_gimbal.toml",
                               "parameter_set", _parameter_set("friction_parameter_set"), None),
    "3-D stiffness file": ("rs25_hotfire.toml", "gimbal.stiffness_file", "../fem_data/gimbal_thrust.npz",
                           "gimbal.stiffness_file", _stiffness, None),
    "flight file's TVC model": ("flight/core_stage.toml", "tvc_model", "../rs25_flight.toml", "tvc_model",
                                _flight_tvc, None),
    "ascent file's flight file": ("flight/ascent.toml", "flight", "core_stage.toml", "flight",
                                  _ascent("flight"), None),
    "ascent file's TVC model": ("flight/ascent.toml", "tvc_model", "../rs25_flight.toml", "tvc_model",
                                _ascent("tvc_model"), None),
    "campaign's ascent file": ("montecarlo/post_separation.toml", "ascent", "../flight/ascent.toml", "ascent",
                               _campaign("ascent"), None),
    "campaign's TVC model": ("montecarlo/post_separation.toml", "tvc_model", "../rs25_hotfire.toml", "tvc_model",
                             _campaign("tvc_model"), 'tvc_model = "../rs25_hotfire.toml"\n'),
    "MASV modal file": ("masv/core_stage_local_modes.toml", "structure.modes",
                        "../../fem_data/thrust_structure_modes_local.npz", "structure.modes", _masv("modes"), None),
    "MASV engine model": ("masv/core_stage_local_modes.toml", "engine.model", "../rs25_hotfire.toml",
                          "engine[0].model", _masv("model"), None),
    "MASV reference configuration": ("masv/core_stage_local_modes.toml", "reference", "core_stage.toml",
                                     "reference", _masv("reference"), None),
}


def _copy_alone(tmp_path: Path, case: str) -> tuple[Path, str]:
    """The case's shipped referring file copied alone to ``tmp_path/a/b`` (deep enough for every
    ``..`` of a reference to stay in ``tmp_path``); returns the copy and the reference."""
    shipped, _, ref, _, _, prefix = CASES[case]
    folder = tmp_path / "a" / "b"
    folder.mkdir(parents=True)
    copy = folder / Path(shipped).name
    text = (MODELS / shipped).read_text()
    copy.write_text((prefix or "") + text)
    return copy, ref


@pytest.mark.parametrize("case", list(CASES))
def test_a_copied_file_finds_the_shipped_target(tmp_path, case):
    shipped, _, ref, _, used, _ = CASES[case]
    copy, ref = _copy_alone(tmp_path, case)
    assert Path(used(copy)) == ((MODELS / shipped).parent / ref).resolve()


@pytest.mark.parametrize("case", list(CASES))
def test_a_target_beside_the_copy_wins_over_the_shipped_one(tmp_path, case):
    shipped, _, ref, _, used, _ = CASES[case]
    copy, ref = _copy_alone(tmp_path, case)
    beside = copy.parent / ref
    beside.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile((MODELS / shipped).parent / ref, beside)   # itself a copy alone: its own references fall back
    assert Path(used(copy)) == beside.resolve()


@pytest.mark.parametrize("case", list(CASES))
def test_a_missing_target_is_one_line_naming_the_file_the_field_and_both_places(tmp_path, case):
    shipped, _, ref, err_field, used, _ = CASES[case]
    copy, ref = _copy_alone(tmp_path, case)
    missing = str(Path(ref).with_name("missing_" + Path(ref).name).as_posix())
    copy.write_text(copy.read_text().replace(f'"{ref}"', f'"{missing}"'))
    with pytest.raises(InputError) as e:
        used(copy)
    msg = str(e.value)
    assert "\n" not in msg
    assert msg.startswith(f"{copy}: ") and msg.split(": ")[1].endswith(err_field), msg
    assert str((copy.parent / missing).resolve()) in msg and "(beside the file)" in msg, msg
    assert str(((MODELS / shipped).parent / missing).resolve()) in msg and "(shipped)" in msg, msg


def test_shipped_models_read_the_same_files():
    """The shipped files resolve as before: their own folder is the shipped one."""
    from taos.model import load_model

    for name, fem in (("rs25_hotfire", "gimbal_thrust"), ("rs25_flight", "gimbal_thrust"),
                      ("rs25_ambient", "gimbal_hanging")):
        files = load_model(MODELS / f"{name}.toml").input_files
        assert {k: v[0] for k, v in files.items()} == {
            "model": str(MODELS / f"{name}.toml"),
            "actuator_parameter_set": str(MODELS / "actuators" / "tvc_actuator.toml"),
            "friction_parameter_set": str(MODELS / "friction" / "rs25_gimbal.toml"),
            "stiffness_file": str(ROOT / "fem_data" / f"{fem}.npz")}
        for path, sha in files.values():
            assert hashlib.sha256(Path(path).read_bytes()).hexdigest() == sha


def test_a_copied_model_has_the_shipped_model_hash(tmp_path):
    from taos.model import load_model

    copy = tmp_path / "rs25_hotfire.toml"
    shutil.copyfile(MODELS / "rs25_hotfire.toml", copy)
    assert load_model(copy).sha256 == load_model(MODELS / "rs25_hotfire.toml").sha256


def test_absolute_references_are_taken_as_given(tmp_path):
    target = ROOT / "fem_data" / "gimbal_thrust.npz"
    assert resolve_reference(str(target), tmp_path / "m.toml", field="gimbal.stiffness_file") == target
    with pytest.raises(InputError, match=r"m\.toml: gimbal\.stiffness_file: expected a file at /") as e:
        resolve_reference(str(tmp_path / "nope.npz"), tmp_path / "m.toml", field="gimbal.stiffness_file")
    assert "(shipped)" not in str(e.value)


def test_no_fallback_leads_out_of_the_shipped_data(tmp_path):
    """``../README.md`` from models/ is the repository's README, not shipped data: only the place
    beside the referring file counts."""
    with pytest.raises(InputError) as e:
        resolve_reference("../README.md", tmp_path / "m.toml", field="x.file")
    assert "(shipped)" not in str(e.value)


def test_a_copied_hotfire_model_runs_the_3d_engine(tmp_path):
    """Issue 38 acceptance: the hot-fire model file copied alone runs ``--engine taos``."""
    copy = tmp_path / "rs25_hotfire.toml"
    shutil.copyfile(MODELS / "rs25_hotfire.toml", copy)
    r = run_cli("freqresp", copy, "--engine", "taos", "--freq-hz", "1", "--json", tmp_path / "fr.json")
    assert r.returncode == 0, r.stderr
    import json
    inputs = json.loads((tmp_path / "fr.json").read_text())["provenance"]["model_inputs"]
    assert inputs["stiffness_file"]["file"] == str(ROOT / "fem_data" / "gimbal_thrust.npz")


def test_a_missing_stiffness_file_exits_2_with_one_line(tmp_path):
    copy = tmp_path / "m.toml"
    copy.write_text((MODELS / "rs25_hotfire.toml").read_text().replace("gimbal_thrust.npz", "missing.npz"))
    r = run_cli("freqresp", copy, "--engine", "taos", "--freq-hz", "1")
    assert r.returncode == 2, r.stderr
    line, = r.stderr.strip().splitlines()
    assert f"{copy}: gimbal.stiffness_file:" in line and "(shipped)" in line, line


def test_the_shipped_fallback_holds_in_the_wheel_layout(tmp_path, monkeypatch):
    """A wheel carries models/ and fem_data/ as taos/shipped/models and taos/shipped/fem_data
    (pyproject.toml): siblings, as in the repository, so ``../fem_data/...`` from the shipped
    models folder is the shipped stiffness file there too."""
    from taos import shipped

    pkg = tmp_path / "site" / "taos" / "shipped"
    for name in ("models", "fem_data"):
        (pkg / name).mkdir(parents=True)
    npz = pkg / "fem_data" / "gimbal_thrust.npz"
    npz.write_bytes(b"")
    monkeypatch.setattr(shipped, "_root", lambda name: pkg / name)
    user = tmp_path / "user" / "rs25_hotfire.toml"
    assert resolve_reference("../fem_data/gimbal_thrust.npz", user, field="gimbal.stiffness_file") == npz.resolve()
    with pytest.raises(InputError, match=r"\(shipped\)"):
        resolve_reference("../fem_data/other.npz", user, field="gimbal.stiffness_file")
