"""Long runs from Python (issue 29): ``Model.run(out=..., checkpoint_every=..., restart=...)``
on [md] and [nbody] models writes the checkpoints ``pdyn run --checkpoint-every`` writes, and a
restart from one ends with the files of the run that was never restarted, byte for byte (and,
for MD, the same thermo records); a checkpoint that does not fit is refused."""

import json
import pathlib

import numpy as np
import pytest

import pdyn

FILES = ["thermo.csv", "traj.xyz", "rdf.csv", "msd.csv",
         "trajectory.csv", "elements.csv", "conservation.csv"]


def _files(d: pathlib.Path):
    return {n: (d / n).read_bytes() for n in FILES if (d / n).exists()}


def _summary(d: pathlib.Path):
    s = json.loads((d / "summary.json").read_text())
    for k in ("checkpoint", "restarted_from", "loop_seconds", "atom_steps_per_second"):
        s.pop(k, None)
    return s


def _restart_matches(model, tmp_path, **opts):
    ref = tmp_path / "ref"
    a = model.run(out=ref, **opts)
    run = tmp_path / "run"
    model.run(out=run, checkpoint_every="300steps", **opts)
    ckpt = run / "checkpoint.json"
    assert ckpt.exists(), "no checkpoint was written"
    head = ckpt.read_text().split("\n", 2)
    steps = json.loads(head[2])["steps"]
    assert steps > 0
    # the files now hold the whole run: the restart cuts them back to the checkpoint's
    # lengths and appends the rest
    b = model.run(out=run, checkpoint_every="300steps", restart=ckpt, **opts)
    assert _files(ref) == _files(run)
    assert len(_files(ref)) >= 2
    assert _summary(ref) == _summary(run)
    assert json.loads((run / "summary.json").read_text())["restarted_from"]["file"] == str(ckpt)
    return a, b


def test_md_restart_from_a_checkpoint_ends_with_the_uninterrupted_files(examples, tmp_path):
    model = pdyn.Model.from_file(examples / "md" / "argon_melting.toml")
    a, b = _restart_matches(model, tmp_path, t_end=10000.0)
    # the thermo records come back from the checkpoint, bit for bit
    assert np.array_equal(np.asarray(a.thermo.data), np.asarray(b.thermo.data))


def test_nbody_restart_from_a_checkpoint_ends_with_the_uninterrupted_files(examples, tmp_path):
    model = pdyn.Model.from_file(examples / "nbody" / "outer_solar_system.toml")
    _restart_matches(model, tmp_path, t_end=400000.0)


def test_a_checkpoint_of_other_options_or_a_mechanics_model_is_refused(examples, tmp_path):
    model = pdyn.Model.from_file(examples / "md" / "argon_melting.toml")
    model.run(out=tmp_path, t_end=4000.0, checkpoint_every="200steps")
    ckpt = tmp_path / "checkpoint.json"
    with pytest.raises(pdyn.ParameterError, match="t_end"):
        model.run(out=tmp_path, t_end=5000.0, restart=ckpt)
    with pytest.raises(pdyn.ParameterError, match="checkpoint_every"):
        model.run(out=tmp_path, t_end=4000.0, checkpoint_every="soon")
    pendulum = next((examples).glob("pendulum*.toml"), None) or examples / "building.toml"
    with pytest.raises(pdyn.ParameterError, match="restart"):
        pdyn.Model.from_file(pendulum).run(restart=ckpt)
