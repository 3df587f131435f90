"""The typed FMU description: what the assembly produces, the build writes and the slave reads
is the same object (round trip through the FMU's resources), for every FMU kind."""
import subprocess
import sys
from dataclasses import fields, is_dataclass
from pathlib import Path

import numpy as np
import pytest

from hydrofmu import description as d
from hydrofmu.assembly import assemble
from hydrofmu.decks.simo import read_couplings
from hydrofmu.fmi.slave import ConnectorSlave, DynamicsSlave, LoadSlave
from hydrofmu.scene import load_scene

MODELS = Path(__file__).parents[1] / "models"
SLAVES = {d.LoadFMU: LoadSlave, d.ConnectorFMU: ConnectorSlave, d.DynamicsFMU: DynamicsSlave}


def same(a, b, where="description"):
    """a and b hold the same values with the same types, field by field."""
    assert type(a) is type(b) or (isinstance(a, (int, float)) and isinstance(b, (int, float))), where
    if is_dataclass(a):
        for f in fields(a):
            same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b), where
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{where}[{i}]")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            same(a[k], b[k], f"{where}.{k}")
    else:
        assert a == b, where


@pytest.fixture(scope="module", params=["joined_barges", "side_by_side", "moored_barge"])
def system(request):
    return assemble(load_scene(MODELS / f"{request.param}.toml"))


def test_round_trip_through_the_resources(system, tmp_path):
    """Every FMU kind: written as the build writes it, read as the slave reads it, equal
    field by field (arrays stay float arrays of the same shape, nested types stay typed);
    the slave instantiated on that folder holds the same description."""
    kinds = set()
    for inst in system.instances:
        folder = tmp_path / inst.name
        folder.mkdir()
        d.write(inst.fmu, folder)
        back = d.read(folder)
        same(inst.fmu, back, inst.name)
        slave = SLAVES[type(inst.fmu)](instance_name=inst.name, resources=str(folder))
        same(inst.fmu, slave.config, inst.name)
        kinds.add(type(back))
    assert kinds >= {d.LoadFMU, d.DynamicsFMU}


def test_coupling_sides_against_the_deck():
    """side_by_side: each barge's load FMU carries the deck's A∞ on side A and A∞ᵀ on side B
    (read independently from the SIMO deck), with the deck's kernels, after a round trip."""
    scene = load_scene(MODELS / "side_by_side.toml")
    system = assemble(scene)
    deck = read_couplings(MODELS / "decks" / "side_by_side.sim", bodies=set(scene.bodies))
    checked = 0
    for c in scene.couplings:
        raw = next(v for v in deck.values() if v.name == c.name)
        for inst in system.instances:
            if not isinstance(inst.fmu, d.LoadFMU):
                continue
            fmu = d.loads(d.dumps(inst.fmu))
            for side in (s for s in fmu.couplings if s.name == c.name):
                want = raw.added_mass if side.side == "A" else raw.added_mass.T
                np.testing.assert_array_equal(side.mass, want)
                got = {(k.dof_a, k.dof_b): k.values for k in side.coupling.kernels}
                assert got.keys() == raw.kernels.keys()
                for key, h in raw.kernels.items():
                    np.testing.assert_array_equal(got[key], h)
                checked += 1
    assert checked == 4          # SELFA, SELFB, and AB on both barges


def test_stored_fits_round_trip():
    """The place for stored state-space realisations: a Fit survives the round trip and the
    coupling model uses it instead of refitting (its order is the stored one)."""
    kernel = d.Kernel(3, 3, 1e4 * np.exp(-0.5 * 0.2 * np.arange(40)))
    fit = d.Fit(3, 3, np.array([[-0.5]]), np.array([1.0]), np.array([1e4]), 0.0)
    c = d.HydroCoupling("C", "a", "a", np.zeros((6, 6)), 0.2, [kernel], "state_space", fits=[fit])
    side = d.CouplingSide(c, "A")
    fmu = d.LoadFMU("x", "a", np.zeros(3), np.zeros(3), "export", [], [side], d.Environment(1025.0, 9.81, 0.0, 0.0))
    back = d.loads(d.dumps(fmu))
    same(fmu, back)
    model = back.couplings[0].coupling.model()
    assert model.fits[(3, 3)].order == 1 and model.fits[(3, 3)].C[0] == 1e4


def test_description_needs_numpy_only():
    """The FMU runtime reads its description at instantiation: numpy is all it imports."""
    code = ("import sys; import hydrofmu.description; "
            "print(sorted(m for m in ('scipy', 'pythonfmu', 'fmpy') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
