"""Mutation-style checks of the deck readers (issue 22, item 7): every valid test deck of
each reader gets systematic edits, and each edit must end in one of

- ``same``: the loads the parsed data gives (through the physics kernels, in-process) equal
  the original's for every entry the original has: a legal variant;
- ``refused``: one InputError naming the mutated file and a line;
- ``not in file``: an entry the scene names is gone (the scene's lookup is then an error
  naming the file: a dropped group identifier whose lines are skipped);
- ``as written``: the edit wrote another legal deck and the reader read exactly it: two rows
  of numbers exchanged (the numbers read are the same multiset), an optional line left out
  (the loads equal those of the original with that line's values given as ``/``, the
  defaults), a row of a table the layout does not count dropped (DeepLines ``*CURRENTPOL``:
  the numbers read are the original's less that row's);

anything else (loads differ without an error, another exception, an error naming no line of
the file) fails.  Edits: drop a line, duplicate a line, append a word (``0.1`` and ``WORD``)
to each keyword line, append a number to each row of numbers (a row with more fields than its
format: issue 31's corpus class), shorten each keyword word to one capital fewer, insert an unknown group
at every line inside each group read, swap each pair of adjacent lines.  Data lines only
(comments and blank lines are not edited).  Counts per reader: ``run_all()``."""
import re
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hydrofmu.decks import aqwa, deeplines, riflex, simo
from hydrofmu.errors import InputError
from hydrofmu.physics.current import CurrentProfile
from hydrofmu.physics.current_polar import CurrentPolar
from hydrofmu.physics.lumped import LumpedBody
from hydrofmu.physics.state import Env, Motion
from hydrofmu.physics.viscous_drag import ViscousDrag

import test_whole_files as tw

ROOT = Path(__file__).resolve().parents[1]
OUTCOMES = ("same", "refused", "not in file", "as written")
_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([EeDd][+-]?\d+)?$")


# --- loads of each reader's data (physics kernels) --------------------------------------
def lumped_loads(comp):
    """A RIFLEX component's loads (tests/test_whole_files.py) and a CONB's freedom codes."""
    return np.concatenate([tw.lumped_loads(comp), np.asarray(getattr(comp, "codes", ()), float)])


def profile_loads(rows):
    """Drag loads of a lumped body at four depths in the profile's current."""
    profile = CurrentProfile.from_rows(rows)
    env = Env(current_speed=profile.surface_speed, current_direction=profile.surface_direction, profile=profile)
    body = LumpedBody("probe", [0.0, 0.0, 0.0], 0.0, 0.0, "GLOBAL", (100.0, 200.0, 300.0), (0.0, 0.0, 0.0))
    return np.concatenate([body.load(Motion(np.array([0.0, 0.0, z]), np.zeros(3), np.zeros(6)), env)
                           for z in (0.0, -7.0, -33.0, -150.0)])


def polar_loads(data, symmetry):
    return CurrentPolar.from_deck(data, symmetry).load(tw.MOTION, tw.ENV)


def drag_loads(data):
    return ViscousDrag("d", data.matrix, data.relative).load(tw.MOTION, tw.ENV)


# --- the readers as the test sees them ---------------------------------------------------
@dataclass
class Reader:
    name: str
    read: object         # path -> {entry: data}
    loads: object        # data -> loads vector
    values: object       # data -> the numbers read (for 'as written')
    grammar: object      # decks.lines.Grammar of the reader's keywords
    comments: tuple
    unknown: str         # a group identifier no reader knows
    uncounted: bool = False   # a table whose rows the layout does not count
    default: object = None    # code of a line -> the same line with its documented defaults, or None


def _fread_default(code):
    """A line of numbers given as '/' each (FREAD's defaults)."""
    if not _number_line(code):
        return None
    return " ".join("/" for _ in code.replace(",", " ").replace("&", " ").split()) + \
        (" &" if code.rstrip().endswith("&") else "")


def _aqwa_default(code):
    """AQWA's settings with their defaults (TYPE=MATRIX, OPTION=ABSOLUTE)."""
    key = code.split("=")[0].strip().upper()
    return {"TYPE": "TYPE=MATRIX", "OPTION": "OPTION=ABSOLUTE"}.get(key)


def _simo_values(d):
    return [*np.ravel(d.added_mass), *(x for k in sorted(d.kernels) for x in d.kernels[k])]


def _wrapped(result, entries):
    """``entries`` (a dict made from a reader's ``result``) keeping the result's Reading."""
    from hydrofmu.decks.lines import with_reading
    return with_reading(entries, result.reading)


def _polar(path):
    return deeplines.read_current_polars(path)


def _polar_loads(data):
    for symmetry in ("none", "xz"):
        try:
            return polar_loads(data, symmetry)
        except InputError:
            continue
    raise InputError(data.path, data.line, "symmetry", "no symmetry fits the table")


def _states(path):
    found = riflex.read_current_states(path)
    return _wrapped(found, {f"{e}/{n}": s.rows for e, states in found.items() for n, s in states.items()})


def _profile(read):
    def reader(path):
        found = read(path)
        return _wrapped(found, {"profile": list(found)})
    return reader


def _reader_simo(bodies):
    return Reader("SIMO", lambda p: simo.read_couplings(p, bodies=bodies), tw.simo_loads, _simo_values,
                  simo.GRAMMAR, ("'",), "UNKNown GROUp DATA")


READERS = {
    "RIFLEX": Reader("RIFLEX", riflex.read_components, lumped_loads,
                     lambda c: [c.am, c.ae, *c.cd, *c.added_mass, *getattr(c, "codes", ())],
                     riflex.GRAMMAR, ("'",), "UNKNown GROUp DATA"),
    "RIFLEX current": Reader("RIFLEX current", _states, profile_loads, lambda rows: np.ravel(rows).tolist(),
                             riflex.GRAMMAR, ("'",), "UNKNown GROUp DATA"),
    "SIMA current": Reader("SIMA current", _profile(simo.read_current_profile), profile_loads,
                           lambda rows: np.ravel(rows).tolist(), simo.GRAMMAR, ("'",), "UNKNown GROUp DATA"),
    "DeepLines": Reader("DeepLines", _polar, _polar_loads,
                        lambda d: [d.xc, d.yc, d.zc, d.surfc, *np.ravel([d.angles, d.cx, d.cy, d.cmz])],
                        deeplines.GRAMMAR, ("!", "#"), "*ALIEN", uncounted=True),
    "DeepLines current": Reader("DeepLines current", _profile(deeplines.read_current_profile),
                                profile_loads, lambda rows: np.ravel(rows).tolist(), deeplines.GRAMMAR,
                                ("!", "#"), "*ALIEN"),
    "AQWA": Reader("AQWA", aqwa.read_viscous_drag, drag_loads, lambda d: np.ravel(d.matrix).tolist(),
                   aqwa.GRAMMAR, ("!", "#"), "*Alien Section", default=_aqwa_default),
}


def decks():
    """(reader, label, text) of every valid test deck: the test data files, the model decks,
    and the whole-file texts of tests/test_whole_files.py and tests/test_current_files.py."""
    import test_current_files as tcf
    data, models = ROOT / "tests" / "data", ROOT / "models" / "decks"
    out = [(_reader_simo(["barge1"]), "tests/data/simo/two_barges.sys", (data / "simo/two_barges.sys").read_text()),
           (_reader_simo(["A"]), "SIMO_BARE", tw.SIMO_BARE),
           (_reader_simo(["A"]), "SIMO_WHOLE", tw.SIMO_WHOLE.format(
               units="m s kg 9.81 1025.0 0.00125 1.188e-6 1.516e-5",
               **dict(am1=1, am16=0.5, am2=2, am3=3, am4=4, am5=5, am61=0.25, am6=6, r1=1.0, r2=0.5, r3=0.25,
                      r4=4.0, r5=2.0))),
           (_reader_simo([]), "models/decks/side_by_side.sim (first 2 groups' structure)",
            _side_by_side(models / "side_by_side.sim"))]
    for f in sorted((data / "riflex").glob("*.inp")) + [models / "joined_barges.inp"]:
        out.append((READERS["RIFLEX"], str(f.relative_to(ROOT)), f.read_text()))
    out.append((READERS["RIFLEX"], "RIFLEX_BARE", tw.RIFLEX_BARE))
    out.append((READERS["RIFLEX"], "RIFLEX_WHOLE", _riflex_whole(tw)))
    out.append((READERS["RIFLEX current"], "test_current_files.RIFLEX",
                tcf.RIFLEX.format(units="/ / / / / /", level1="0.0, 0.0, 1.0")))
    out.append((READERS["SIMA current"], "SIMA current file",
                "' number of current levels\n3\n' zlevel direction current\n0.0 0.0 1.0\n"
                "-20.0, 90.0, 0.4\n-1.0D2 90.0 0.1\n"))
    for f in sorted((data / "deeplines").glob("*.dat")) + [models / "barge_current.dpl"]:
        out.append((READERS["DeepLines"], str(f.relative_to(ROOT)), f.read_text()))
    out.append((READERS["DeepLines"], "POLAR", tw.POLAR))
    out.append((READERS["DeepLines"], "DEEPLINES_WHOLE", tw.DEEPLINES_WHOLE))
    out.append((READERS["DeepLines current"], "test_current_files.DEEPLINES", tcf.DEEPLINES))
    for f in sorted((data / "aqwa").glob("*.dat")) + [models / "barge_viscous.aqwa"]:
        out.append((READERS["AQWA"], str(f.relative_to(ROOT)), f.read_text()))
    out.append((READERS["AQWA"], "DRAG", tw.DRAG))
    out.append((READERS["AQWA"], "AQWA_WHOLE", tw.AQWA_WHOLE))
    return out


def _riflex_whole(tw):
    v = dict(am1=2500.0, ae1=4.0, cd1=120.0, cd2=130.0, cd3=300.0, amx1=1000.0, amy1=1100.0, amz1=2500.0,
             am2=100.0, ae2=0.05, cd4=10.0, amx2=20.0)
    return tw.RIFLEX_WHOLE.format(units="s m kg N 9.81 1.0", **{k: repr(x) for k, x in v.items()})


def _side_by_side(path):
    """The model's SIMO deck with each kernel cut to its first 8 samples (its structure
    whole: body data, three couplings, every block): 941 lines of samples would make the
    suite slow and add only more of the same kernel-line edits."""
    lines, out, k = path.read_text().splitlines(), [], 0
    while k < len(lines):
        words = lines[k].split()
        if len(words) == 3 and all(w.isdigit() for w in words) and int(words[0]) > 8:
            out.append(f"8 {words[1]} {words[2]}")
            samples = []
            k += 1
            while len(samples) < 8:
                samples += lines[k].replace("&", " ").split()
                k += 1
            while lines[k - 1].rstrip().endswith("&"):
                k += 1
            out.append(" ".join(samples[:8]))
            continue
        out.append(lines[k])
        k += 1
    return "\n".join(out) + "\n"


# --- edits ------------------------------------------------------------------------------
def _data_lines(text, comments):
    lines = text.splitlines()
    return lines, [i for i, t in enumerate(lines) if t.strip() and not t.strip().startswith(comments)]


def _code(text, comments):
    """A line's data part (before a comment mark)."""
    cut = min([i for i in (text.find(c) for c in comments) if i >= 0], default=len(text))
    return text[:cut]


def _keyword_lines(reader, lines, index):
    """Indices of the lines that are one of the reader's keywords, with the keyword."""
    from hydrofmu.decks.lines import Line
    out = []
    for i in index:
        line = Line("k", i + 1, _code(lines[i], reader.comments).strip())
        if not line.text:
            continue
        try:
            key = reader.grammar.find(line)
        except InputError:
            key = None
        if key is not None:
            out.append((i, key))
    return out


def _shortened(reader, text, key):
    """Each keyword word written one capital short (one letter short for exact keywords)."""
    code = _code(text, reader.comments)
    words = reader.grammar.words(_L(code))
    out = []
    for k, (caps, _) in enumerate(key.words[:len(words)]):
        short = caps[:-1]
        if len(short) == 0 or (short == "*"):
            continue
        word = words[k]
        start = code.upper().find(word.upper())
        out.append(code[:start] + short + code[start + len(word):])
    return out


class _L:
    def __init__(self, text):
        self.text, self.words = text.strip(), text.replace(",", " ").split()


def edits(reader, text, reading):
    """(kind, first line index touched, mutated text) of every edit of ``text``."""
    lines, index = _data_lines(text, reader.comments)
    join = "\n".join
    out = []
    for i in index:
        out.append(("drop a line", i, join(lines[:i] + lines[i + 1:]) + "\n"))
        out.append(("duplicate a line", i, join(lines[:i + 1] + lines[i:]) + "\n"))
        code = _code(lines[i], reader.comments).rstrip()
        if _number_line(code) and not code.endswith("&"):
            out.append(("append a number", i, join(lines[:i] + [code + " 0.1"] + lines[i + 1:]) + "\n"))
    for a, b in zip(index, index[1:]):
        out.append(("swap two lines", a, join(lines[:a] + [lines[b]] + lines[a + 1:b] + [lines[a]] + lines[b + 1:])
                     + "\n"))
    for i, key in _keyword_lines(reader, lines, index):
        if key.spelling == "END":
            continue
        code = _code(lines[i], reader.comments).rstrip()
        for word in ("0.1", "WORD"):
            out.append(("append a word", i, join(lines[:i] + [code + " " + word] + lines[i + 1:]) + "\n"))
        for short in _shortened(reader, lines[i], key):
            out.append(("shorten a keyword", i, join(lines[:i] + [short] + lines[i + 1:]) + "\n"))
    # an unknown group inside each group read: after every line from its keyword to its last
    starts = sorted({n for _, n in reading.used} | {n for _, n, _ in reading.skipped})
    for name, first in reading.used:
        later = [n for n in starts if n > first]
        last = (later[0] - 1) if later else len(lines)
        for i in index:
            if first - 1 <= i < last - 1 and any(j > i and j <= last - 1 for j in index):
                out.append(("insert an unknown group", i,
                            join(lines[:i + 1] + [reader.unknown] + lines[i + 1:]) + "\n"))
    return out


# --- outcomes ---------------------------------------------------------------------------
def _numbers(text):
    return [0.0 if w == "/" else float(w.replace("D", "E").replace("d", "e"))
            for w in text.replace(",", " ").replace("&", " ").split()]


def _number_line(text):
    words = text.replace(",", " ").replace("&", " ").split()
    return bool(words) and all(w == "/" or _NUMBER.match(w) for w in words)


def _close(a, b):
    return np.array_equal(np.asarray(a), np.asarray(b))


def outcome(reader, path, original, kind, i, lines_before, text):
    """The outcome of one edit (an element of OUTCOMES), or raise AssertionError."""
    path.write_text(text)
    try:
        got = reader.read(path)
    except InputError as exc:
        assert Path(exc.path) == path, f"{kind} at line {i + 1}: error names {exc.path}, not the deck: {exc}"
        assert exc.line is not None or "no " in exc.message, f"{kind} at line {i + 1}: error names no line: {exc}"
        return "refused"
    if any(name not in got for name in original):
        return "not in file"
    try:
        loads = {name: reader.loads(got[name]) for name in original}
    except InputError as exc:
        return "refused" if Path(exc.path) == path else _fail(kind, i, f"error from elsewhere: {exc}")
    base = {name: reader.loads(original[name]) for name in original}
    if all(_close(loads[n], base[n]) for n in original):
        return "same"
    codes = [_code(t, reader.comments) for t in lines_before]
    if kind == "swap two lines":
        j = next(k for k in range(i + 1, len(codes)) if codes[k].strip())
        if _number_line(codes[i]) and _number_line(codes[j]) and \
                Counter(_all_values(reader, got, original)) == Counter(_all_values(reader, original, original)):
            return "as written"
    default = (reader.default or _fread_default)(codes[i]) if kind == "drop a line" else None
    if default is not None:
        path.write_text("\n".join(lines_before[:i] + [default] + lines_before[i + 1:]) + "\n")
        try:
            expected = reader.read(path)
            if all(_close(reader.loads(expected[n]), loads[n]) for n in original):
                return "as written"
        except InputError:
            pass
    if kind == "drop a line" and _number_line(codes[i]):
        if reader.uncounted and Counter(_all_values(reader, original, original)) - Counter(_numbers(codes[i])) \
                == Counter(_all_values(reader, got, original)):
            return "as written"
    _fail(kind, i, f"loads differ without an error:\n{text}")


def _all_values(reader, data, names):
    return [float(x) for n in names for x in reader.values(data[n])]


def _fail(kind, i, message):
    raise AssertionError(f"{kind} at line {i + 1}: {message}")


def run_all(tmp, only=None):
    """{reader name: Counter of outcomes, plus 'edits' and 'decks'}; fails on the first bad edit."""
    counts = {}
    for n, (reader, label, text) in enumerate(decks()):
        if only and reader.name not in only:
            continue
        path = Path(tmp) / f"deck{n}{Path(label.split()[0]).suffix or '.txt'}"
        path.write_text(text)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            original = reader.read(path)
            reading = original.reading
            c = counts.setdefault(reader.name, Counter())
            c["decks"] += 1
            lines = text.splitlines()
            for kind, i, mutated in edits(reader, text, reading):
                try:
                    c[outcome(reader, path, original, kind, i, lines, mutated)] += 1
                except AssertionError as exc:
                    raise AssertionError(f"{reader.name} deck {label}: {exc}") from None
                c["edits"] += 1
                c[kind] += 1
    return counts


def table(counts):
    """The README's table of the counts."""
    rows = ["| reader | decks | edits | same loads | refused (file, line) | entry gone (scene refuses) | "
            "read as written |", "|---|---|---|---|---|---|---|"]
    for name, c in counts.items():
        rows.append(f"| {name} | {c['decks']} | {c['edits']} | {c['same']} | {c['refused']} | {c['not in file']} | "
                    f"{c['as written']} |")
    total = sum(counts.values(), Counter())
    rows.append(f"| all | {total['decks']} | {total['edits']} | {total['same']} | {total['refused']} | "
                f"{total['not in file']} | {total['as written']} |")
    return "\n".join(rows)
