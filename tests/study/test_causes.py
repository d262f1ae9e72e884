"""The recorded causes of disagreements: loaded, validated, and named in errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from archmetrics.study.causes import KINDS, load_causes
from archmetrics.study.findings import FINDINGS
from archmetrics.study.manifest import VARIANTS, ManifestError

GOOD = """
[[cause]]
finding = "wdb-p2p-coupling"
variant = "idiomatic"
kind = "subject"
elements = ["server/wdb-server.c: one accept loop"]
text = "one connection serves every operation"
"""


def test_the_bundled_causes_load_and_name_known_findings() -> None:
    causes = load_causes()
    ids = {f.id for f in FINDINGS}
    for (finding, variant), cause in causes.items():
        assert finding in ids and variant in VARIANTS and cause.kind in KINDS
        assert cause.describe().startswith(f"{cause.kind}: ")


def test_a_cause_is_read(tmp_path: Path) -> None:
    (tmp_path / "c.toml").write_text(GOOD)
    cause = load_causes(tmp_path / "c.toml")["wdb-p2p-coupling", "idiomatic"]
    assert cause.describe() == (
        "subject: one connection serves every operation [server/wdb-server.c: one accept loop]"
    )


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('kind = "subject"', 'kind = "luck"'), "cause\\[0\\]: kind must be one of"),
        (('variant = "idiomatic"', 'variant = "x"'), "cause\\[0\\]: variant must be one of"),
        (('elements = ["server/wdb-server.c: one accept loop"]', "elements = []"), "'elements'"),
        (('text = "one connection serves every operation"', ""), "'text' must be a non-empty"),
        (("[[cause]]", "[[cause]]"), None),
    ],
)
def test_bad_causes_are_named(tmp_path: Path, change: tuple[str, str], message: str | None) -> None:
    file = tmp_path / "c.toml"
    file.write_text(GOOD.replace(*change) if message else GOOD + GOOD)
    expected = message or "cause\\[1\\]: wdb-p2p-coupling \\(idiomatic\\) given twice"
    with pytest.raises(ManifestError, match=expected) as error:
        load_causes(file)
    assert "c.toml" in str(error.value)
