"""compute_change end to end on hand-built facts: statuses, locations, exclusions, notes."""

from __future__ import annotations

import json

import pytest

from archmetrics.changeset import (
    ChangeReport,
    Coupling,
    ElementChange,
    FilePair,
    Location,
    LocationRules,
    Status,
    compute_change,
)
from archmetrics.coupling.elements import Element
from archmetrics.facts import Decision, FileFacts, Function, Span, Statement


def facts(
    path: str, *texts: str, decisions: int = 0, generated: bool = False, parsed: bool = True
) -> FileFacts:
    """A file whose statements are ``texts`` (one per line) in one function of v_g 1+decisions."""
    statements = tuple(Statement("stmt", Span(n, n), t) for n, t in enumerate(texts, 1))
    function = Function(
        "f",
        "f",
        Span(1, max(len(texts), 1)),
        tuple(Decision("if", 1) for _ in range(decisions)),
        len(texts),
    )
    return FileFacts(
        path, "python", statements, (function,), sloc=len(texts), parsed=parsed, generated=generated
    )


RULES = LocationRules.from_mapping(
    {"new": ["wdb/**"], "framework": ["proxy/**"]}, exclude=["generated/**"]
)


def run(
    *pairs: FilePair,
    coupling_pre: dict[str, Coupling] | None = None,
    coupling_post: dict[str, Coupling] | None = None,
    dynamic_pre_zero: bool = False,
) -> ChangeReport:
    return compute_change(
        pairs, None, RULES, coupling_pre, coupling_post, dynamic_pre_zero=dynamic_pre_zero
    )


def element(report: ChangeReport, name: str) -> ElementChange:
    return next(e for e in report.elements if e.element == name)


def test_statuses_and_per_element_counts() -> None:
    report = run(
        FilePair(None, facts("wdb/store.py", "a", "b", decisions=1)),
        FilePair(facts("client/old.py", "x", "y"), None),
        FilePair(facts("client/main.py", "p = 1", "q"), facts("client/main.py", "p = 2", "q", "r")),
        FilePair(facts("client/same.py", "s"), facts("client/same.py", "s")),
    )
    by_name = {e.element: e for e in report.elements}
    assert by_name["wdb/store.py"].status is Status.ADDED
    assert by_name["wdb/store.py"].pre is None
    assert by_name["wdb/store.py"].location is Location.NEW
    assert by_name["client/old.py"].status is Status.REMOVED
    assert by_name["client/old.py"].post is None
    assert (by_name["client/old.py"].removed, by_name["client/old.py"].added) == (2, 0)
    main = by_name["client/main.py"]
    assert main.status is Status.MODIFIED
    assert (main.added, main.removed, main.modified) == (1, 0, 1)
    assert main.pre is not None and main.post is not None
    assert (main.pre.loc, main.post.loc, main.pre.vg) == (2, 3, 1)
    assert by_name["client/same.py"].status is Status.UNCHANGED

    base = report.location(Location.BASE)
    # base: pre λ = 2 (old) + 2 (main) + 1 (same) = 5, post λ = 3 + 1 = 4
    assert (base.loc_pre, base.loc_post, base.added, base.removed, base.modified) == (5, 4, 1, 2, 1)
    assert (base.vg_pre, base.vg_post) == (3, 2)
    new = report.location(Location.NEW)
    assert (new.loc_pre, new.loc_post, new.added, new.vg_post) == (0, 2, 2, 2)
    assert report.total.changes == 6


def test_exclusions_are_listed_with_reasons_and_count_nowhere() -> None:
    report = run(
        FilePair(None, facts("generated/stub.py", "a")),
        FilePair(None, facts("wdb/gen.py", "a", generated=True)),
        FilePair(facts("client/bin.py", parsed=False), facts("client/bin.py", "a")),
        FilePair(None, facts("wdb/real.py", "a")),
    )
    assert [(x.path, x.reason) for x in report.excluded] == [
        ("client/bin.py", "not_parsed"),
        ("generated/stub.py", "exclude:generated/**"),
        ("wdb/gen.py", "generated"),
    ]
    assert [e.element for e in report.elements] == ["wdb/real.py"]
    assert report.total.changes == 1


def test_generated_files_can_be_kept() -> None:
    rules = LocationRules.from_mapping({"new": ["wdb/**"]}, exclude_generated=False)
    report = compute_change(
        [FilePair(None, facts("wdb/gen.py", "a", generated=True))], None, rules, None, None
    )
    assert report.excluded == () and report.total.added == 1


def test_a_renamed_file_follows_itself_into_its_new_element() -> None:
    report = run(FilePair(facts("client/util.py", "a", "b"), facts("wdb/util.py", "a", "c")))
    (moved,) = report.elements
    assert (moved.element, moved.location, moved.status) == (
        "wdb/util.py",
        Location.NEW,
        Status.MODIFIED,
    )
    assert (moved.added, moved.removed, moved.modified) == (0, 0, 1)
    assert moved.pre is not None and moved.pre.loc == 2


def test_rename_inside_one_element_diffs_the_statements() -> None:
    grouping = [Element("comp", ("src/a.py", "src/b.py"), ("python",))]
    report = compute_change(
        [FilePair(facts("src/a.py", "x", "y"), facts("src/b.py", "x", "y2"))],
        grouping,
        RULES,
        None,
        None,
    )
    (comp,) = report.elements
    assert (comp.element, comp.status, comp.files) == ("comp", Status.MODIFIED, ("src/b.py",))
    assert (comp.added, comp.removed, comp.modified) == (0, 0, 1)


def test_coupling_values_enter_the_deltas_and_missing_ones_are_flagged() -> None:
    pairs = (
        FilePair(facts("client/a.py", "x"), facts("client/a.py", "x", "import wdb")),
        FilePair(None, facts("wdb/w.py", "y")),
    )
    report = run(
        *pairs,
        coupling_pre={"client/a.py": Coupling(1, 2, 3, 4)},
        coupling_post={"client/a.py": Coupling(1, 3, 5, 4)},
    )
    base = report.location(Location.BASE)
    assert (base.delta_s_a, base.delta_s_e, base.delta_d_a, base.delta_d_e) == (0, 1, 2, 0)
    new = report.location(Location.NEW)
    assert any(n.startswith("coupling_missing_post: element 'wdb/w.py'") for n in new.notes)
    assert any(n.startswith("coupling_missing_post") for n in report.total.notes)
    assert not any("coupling_missing" in n for n in base.notes)


def test_thesis_dynamic_convention_zeroes_pre_dynamic_coupling() -> None:
    pairs = (FilePair(facts("client/a.py", "x"), facts("client/a.py", "x")),)
    coupling = {"client/a.py": Coupling(1, 1, 2, 2)}
    measured = run(*pairs, coupling_pre=coupling, coupling_post=coupling)
    thesis = run(*pairs, coupling_pre=coupling, coupling_post=coupling, dynamic_pre_zero=True)
    assert measured.total.delta_d_a == 0
    assert (thesis.total.delta_d_a, thesis.total.delta_d_e, thesis.total.delta_s_a) == (2, 2, 0)
    assert any(n.startswith("dynamic_pre_zero") for n in thesis.total.notes)


def test_no_coupling_is_flagged_everywhere() -> None:
    report = run(FilePair(None, facts("wdb/w.py", "y")))
    for _, summary in report.locations:
        assert any(n.startswith("coupling_not_measured_pre") for n in summary.notes)


def test_mixed_locations_take_the_majority_and_are_flagged() -> None:
    grouping = [Element("mix", ("wdb/a.py", "wdb/b.py", "lib/c.py"), ("python",))]
    report = compute_change(
        [FilePair(None, facts(p, "s")) for p in ("wdb/a.py", "wdb/b.py", "lib/c.py")],
        grouping,
        RULES,
        None,
        None,
    )
    (mix,) = report.elements
    assert mix.location is Location.NEW
    new = report.location(Location.NEW)
    assert new.added == 3
    assert any(n.startswith("element_mixed_locations: element 'mix'") for n in new.notes)


def test_a_path_in_two_elements_is_refused() -> None:
    grouping = [Element(n, ("a.py",), ("python",)) for n in ("one", "two")]
    with pytest.raises(ValueError, match="two elements"):
        compute_change([FilePair(None, facts("a.py"))], grouping, RULES, None, None)


def test_report_json_shape() -> None:
    report = run(FilePair(facts("client/a.py", "x = 1"), facts("client/a.py", "x = 2")))
    data = json.loads(json.dumps(report.to_dict()))
    assert list(data) == ["locations", "total", "elements", "excluded"]
    assert list(data["locations"]) == ["base", "new", "framework"]
    (record,) = data["elements"]
    assert list(record) == [
        "element",
        "location",
        "files",
        "status",
        "pre",
        "post",
        "added",
        "removed",
        "modified",
        "links_added",
        "links_removed",
    ]
    assert list(record["pre"]) == ["loc", "sloc", "vg", "s_a", "s_e", "d_a", "d_e"]
    assert record["status"] == "modified" and record["modified"] == 1


def test_greedy_pairing_is_flagged_in_the_summary(monkeypatch: pytest.MonkeyPatch) -> None:
    from archmetrics.changeset import pairing

    monkeypatch.setattr(pairing, "EXACT_PAIRING_CELLS", 1)
    report = run(
        FilePair(
            facts("client/a.py", "a = 1", "b = 1"),
            facts("client/a.py", "a = 2", "b = 2", "c = 2"),  # 2 x 3: a choice, so greedy
        )
    )
    assert report.total.modified == 2
    assert any(n.startswith("pairing_approximate: 'client/a.py'") for n in report.total.notes)
    assert any(n.startswith("pairing_approximate") for n in report.location(Location.BASE).notes)


def test_a_file_leaving_an_excluded_folder_counts_as_added() -> None:
    report = run(FilePair(facts("generated/api.py", "a", "b"), facts("client/api.py", "a", "b")))
    assert [(x.path, x.reason) for x in report.excluded] == [
        ("generated/api.py", "exclude:generated/**")
    ]
    (api,) = report.elements
    assert (api.element, api.status, api.added) == ("client/api.py", Status.ADDED, 2)
