"""Property tests: endpoint and callee helpers accept any text without crashing."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from archmetrics.coupling.dynamic import matches, normalize_callee
from archmetrics.coupling.endpoints import literal, normalize
from archmetrics.coupling.rules import ENDPOINT_TYPES


@given(st.text(max_size=60))
def test_literal_never_raises(text: str) -> None:
    literal(text)


@given(st.sampled_from(sorted(ENDPOINT_TYPES)),
       st.one_of(st.text(max_size=40), st.integers(), st.binary(max_size=10)))  # fmt: skip
def test_normalize_gives_a_typed_key_or_none(kind: str, value: object) -> None:
    key = normalize(kind, value)  # type: ignore[arg-type]
    assert key is None or (":" in key and key.split(":", 1)[1])


@given(st.text(max_size=60))
def test_normalize_callee_is_idempotent_and_a_callee_matches_itself_as_a_pattern(text: str) -> None:
    once = normalize_callee(text)
    assert normalize_callee(once) == once
    if once and not any(c in once for c in "*?[]"):
        assert matches(once, text)
