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
