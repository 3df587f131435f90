"""Issue 22, item 7: the mutation suite of the deck readers (tests/deck_mutations.py):
every valid test deck of each reader, every systematic edit, each edit the same loads,
refused with file and line, or read exactly as written; never different loads without a
word.  The reliability page's table (docs/reliability.md) is this test's output."""
import re

from deck_mutations import READERS, ROOT, run_all, table


def test_every_edit_of_every_deck_is_read_as_written_or_refused(tmp_path):
    counts = run_all(tmp_path)
    assert set(counts) == {r.name for r in READERS.values()} | {"SIMO"}
    for name, c in counts.items():
        assert c["edits"] == sum(c[k] for k in ("same", "refused", "not in file", "as written")), name
        assert c["refused"] > 0, name
    assert sum(c["same"] for c in counts.values()) > 0    # legal variants exist and build the same loads
    page = (ROOT / "docs" / "reliability.md").read_text()
    found = re.search(r"<!-- mutation counts -->\n(.*?)\n<!-- /mutation counts -->", page, re.S)
    assert found, "docs/reliability.md: the mutation counts' table is missing"
    assert found.group(1) == table(counts), "docs/reliability.md's mutation table is out of date; it should read:\n" \
        + table(counts)


import pytest  # noqa: E402

from deck_mutations import _code, _data_lines, _number_line, decks  # noqa: E402


@pytest.mark.parametrize("name", sorted({r.name for r, _, _ in decks()}))
def test_a_row_with_more_fields_is_refused_at_its_line(tmp_path, name):
    """Issue 31's class, per reader: a number appended to any row of numbers inside a group
    the reader reads (a row with more fields than its format) is an error naming the file and
    that row's line (the physical line of a continued one), never read from its first fields
    (a WAMIT .3 row of 8 numbers was).  DeepLines' *CURPROF levels are a free list: one more
    level is legal there, and the *CURRENT rows that no longer fit are the error."""
    import warnings
    from hydrofmu.errors import InputError
    checked = 0
    for n, (reader, label, text) in enumerate(d for d in decks() if d[0].name == name):
        path = tmp_path / f"deck{n}.txt"
        path.write_text(text)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reading = reader.read(path).reading
        starts = sorted({k for _, k in reading.used} | {k for _, k, _ in reading.skipped})
        used = [(k, next((s for s in starts if s > k), 10 ** 9)) for _, k in reading.used]
        lines, index = _data_lines(text, reader.comments)
        for i in index:
            code = _code(lines[i], reader.comments).rstrip()
            if not (_number_line(code) and not code.endswith("&") and any(a < i + 1 < b for a, b in used)):
                continue
            path.write_text("\n".join(lines[:i] + [code + " 0.1"] + lines[i + 1:]) + "\n")
            with warnings.catch_warnings(), pytest.raises(InputError) as err:
                warnings.simplefilter("ignore")
                reader.read(path)
            exact = err.value.line == i + 1
            free_list = name == "DeepLines current" and err.value.line > i + 1   # *CURPROF: ZCUR a free list
            assert err.value.path == str(path) and (exact or free_list), (label, i + 1, str(err.value))
            checked += 1
    assert checked > 0
