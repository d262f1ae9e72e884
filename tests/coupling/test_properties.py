"""Property tests: endpoint and callee helpers accept any text without crashing."""

from __future__ import annotations

import functools

from hypothesis import given, settings
from hypothesis import strategies as st

from archmetrics.coupling.dynamic import RuleIndex, matches, normalize_callee, rule_index
from archmetrics.coupling.endpoints import literal, normalize
from archmetrics.coupling.loader import load_rule_packs
from archmetrics.coupling.rules import ENDPOINT_TYPES, SiteKind


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
    # a name with no glob character, nothing gitignore reads otherwise (a leading ! or #, a
    # / or a \\) and no space or ( (which a rule pack's match may not hold) matches itself
    plain = not any(c in once for c in "*?[]/\\(") and not any(c.isspace() for c in once)
    if once and plain and once[0] not in "!#":
        assert matches(once, text)


@functools.cache
def _indexes() -> list[RuleIndex]:
    rules = load_rule_packs([]).rules
    return [
        rule_index(tuple(r for r in rules if r.site is site and language in r.languages))
        for language in ("c", "cpp", "python")
        for site in (SiteKind.CALL, SiteKind.DEFINITION)
    ]


_NAMES = sorted({p.replace("*", "x") for r in load_rule_packs([]).rules for p in r.match})


@settings(deadline=None)  # no timing in tests: a loaded machine takes 200 ms for one
@given(
    st.one_of(
        st.sampled_from(_NAMES),
        st.builds(lambda a, b: f"{a}.{b}", st.text(max_size=8), st.sampled_from(_NAMES)),
        st.builds(lambda a, b: f"{a}->{b}", st.text(max_size=8), st.sampled_from(_NAMES)),
        st.text(max_size=30),
    )
)
def test_a_callee_a_rule_matches_is_never_filtered_out(callee: str) -> None:
    """The link filter's answer (may_match) is a superset of what choose finds: a file it
    says no to has no link site."""
    for index in _indexes():
        if index.choose(callee) is not None or index.choose(callee, True) is not None:
            assert index.may_match([callee])
