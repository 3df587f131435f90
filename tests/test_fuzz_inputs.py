"""Fuzz: seeded random mutations of every scene and deck in models/ and tests/data, built
in-process through the CLI.  Each mutation either builds (a complete scene folder, nothing
else) or ends in exactly one ``error:`` line naming the file and the line or key path, exit
code 2, and nothing written.  Never a traceback."""
import contextlib
import io
import random
import re
import shutil


from conftest import MODELS, ROOT
from hydrofmu.cli import main

DATA = ROOT / "tests" / "data"
# tests/data has no scene: this one uses every deck there (names as in the decks)
DATA_SCENE = """
[bodies.hull]
mass = 1.0e6
inertia = [1.0e8, 1.0e8, 1.0e8]
[[bodies.hull.effects]]
type = "aqwa_viscous_drag"
deck = "data/aqwa/viscous_drag_manual.dat"
body = "FPSO"
[[bodies.hull.effects]]
type = "aqwa_viscous_drag"
name = "named"
deck = "data/aqwa/viscous_drag_named.dat"
body = "Hull B"
[[bodies.hull.effects]]
type = "deeplines_current_polar"
deck = "data/deeplines/currentpol_manual.dat"
structure = "FPSO"
symmetry = "xz+yz"
[[bodies.hull.effects]]
type = "deeplines_current_polar"
name = "spar"
deck = "data/deeplines/currentpol_multi.dat"
structure = "SPAR"
symmetry = "xz+yz"
[[bodies.hull.effects]]
type = "riflex_body"
deck = "data/riflex/body_manual.inp"
component = "buoy1"
offset = [0.0, 0.0, 0.0]
[[bodies.hull.effects]]
type = "riflex_body"
name = "float"
deck = "data/riflex/inpmod_mixed.inp"
component = "float"
offset = [1.0, 0.0, 0.0]
[joints.hinge]
a = "hull"
a_point = [10.0, 0.0, 0.0]
deck = "data/riflex/conb_manual.inp"
component = "hinge"
[bodies.barge1]
mass = 1.0e6
inertia = [1.0e8, 1.0e8, 1.0e8]
position = [0.0, 50.0, 0.0]
[bodies.barge2]
mass = 1.0e6
inertia = [1.0e8, 1.0e8, 1.0e8]
position = [0.0, 90.0, 0.0]
[[couplings]]
deck = "data/simo/two_barges.sys"
coupling = "cpl12"
[[couplings]]
deck = "data/simo/two_barges.sys"
coupling = "cpl22"
"""
NUMBER = re.compile(rb"(?<![\w.])[-+]?(\d+\.?\d*|\.\d+)([eEdD][-+]?\d+)?(?![\w.])")
GARBAGE = [b"NaN", b"nan", b"inf", b"-inf", b"+Infinity", b"1e400", b"-1e400", b"1.2.3", b"x", b"1e",
           b"--1", b"0x10", b"1,5", b"", b"\xe9", b"1e-400", b"9" * 400]
CASES_PER_FILE = 20   # x 20 files = 400 mutations


def mutate(data, rng):
    """One random mutation of a file's bytes: (description, new bytes)."""
    lines = data.split(b"\n")
    k = rng.randrange(len(lines))
    op = rng.choice(["drop line", "duplicate line", "drop token", "duplicate token", "number",
                     "number", "number", "bom", "truncate", "crlf", "latin-1 byte"])
    if op == "drop line":
        return op, b"\n".join(lines[:k] + lines[k + 1:])
    if op == "duplicate line":
        return op, b"\n".join(lines[:k + 1] + lines[k:])
    if op in ("drop token", "duplicate token"):
        words = lines[k].split(b" ")
        j = rng.randrange(len(words))
        words[j:j + 1] = [] if op == "drop token" else [words[j], words[j]]
        lines[k] = b" ".join(words)
        return op, b"\n".join(lines)
    if op == "number":
        found = list(NUMBER.finditer(data))
        if found:
            m = rng.choice(found)
            bad = rng.choice(GARBAGE)
            return f"number {m.group().decode()} -> {bad[:12]!r}", data[:m.start()] + bad + data[m.end():]
        op = "truncate"
    if op == "bom":
        return op, b"\xef\xbb\xbf" + data
    if op == "crlf":
        return op, data.replace(b"\n", b"\r\n")
    if op == "latin-1 byte":
        at = rng.randrange(len(data) + 1)
        return op, data[:at] + b"\xe9" + data[at:]
    at = rng.randrange(len(data))
    return f"truncate at {at}", data[:at]


def corpus(tmp):
    """(scene, file to mutate) pairs: every scene of models/ with each of its decks, and
    the tests/data scene with each deck of tests/data; all copied into ``tmp``."""
    shutil.copytree(MODELS, tmp / "models")
    # state-space fits (the design preset) cost seconds per build check: fuzz the decks
    # with the default convolution memory instead (the fits are tested elsewhere)
    scene = tmp / "models" / "side_by_side.toml"
    scene.write_text(scene.read_text().replace('preset = "design"', ''))
    scene = tmp / "models" / "buoy_in_waves.toml"
    scene.write_text(scene.read_text().replace('method = "state_space"', 'method = "convolution"'))
    shutil.copytree(DATA, tmp / "data")
    (tmp / "data.toml").write_text(DATA_SCENE)
    pairs = []
    for scene in sorted((tmp / "models").glob("*.toml")):
        decks = sorted({tmp / "models" / d for d in re.findall(r'deck = "([^"]+)"', scene.read_text())})
        pairs += [(scene, f) for f in [scene, *decks]]
    # the decks the data scene reads (a file it does not name cannot change its build)
    data_decks = sorted({tmp / d for d in re.findall(r'deck = "([^"]+)"', DATA_SCENE)})
    pairs += [(tmp / "data.toml", f) for f in [tmp / "data.toml", *data_decks]]
    return pairs


def build(scene, out, check=False):
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(["build", str(scene), "-o", str(out)] + ["--check"] * check)
    return code, err.getvalue()


def test_mutated_inputs_build_or_fail_with_one_line(tmp_path):
    pairs = corpus(tmp_path)
    assert len(pairs) >= 15 and {p[1].suffix for p in pairs} >= {".toml", ".dat", ".inp", ".sys", ".aqwa"}
    for scene, _ in {(s, None) for s, _ in pairs}:     # the unmutated inputs build
        assert build(scene, tmp_path / "ok")[0] == 0
    shutil.rmtree(tmp_path / "ok")
    rng = random.Random(20261123)
    counts = {0: 0, 2: 0}
    real_builds = set()
    for scene, target in pairs:
        original = target.read_bytes()
        for case in range(CASES_PER_FILE):
            what, data = mutate(original, rng)
            target.write_bytes(data)
            out = tmp_path / "out" / f"{target.stem}-{case}"
            # a full build is slow (~0.5 s): `build --check` does every check of the build
            # and writes nothing; the first mutation per scene that passes is built for real
            code, err = build(scene, out, check=True)
            if code == 0 and scene not in real_builds:
                code, err = build(scene, out)
                real_builds.add(scene)
                assert code == 0, f"check passed, build failed: {err}"
            label = f"{target.name} case {case} ({what}): exit {code}\n{err}"
            assert "Traceback" not in err, label
            errors = [line for line in err.splitlines() if line.startswith("error:")]
            if code == 0:
                assert not errors, label
                if out.exists():
                    built = [p for p in out.iterdir()]
                    assert len(built) == 1 and (built[0] / "manifest.json").is_file(), label   # no leftovers
                    shutil.rmtree(out)
            else:
                assert code == 2, label
                assert len(errors) == 1 and err.splitlines()[-1] == errors[0], label
                # the scene's file, then a line number or a key path, then the field
                assert re.match(rf"error: \S*{scene.name}(:\d+)?: [\w.\[\]\"' -]+: ", errors[0]), label
                if target != scene:    # a deck's error names the deck
                    assert target.name in errors[0], label
                assert not out.exists(), label                                  # nothing written
            counts[code] += 1
        target.write_bytes(original)
    assert counts[0] > 20 and counts[2] > 100, counts   # both outcomes are exercised
