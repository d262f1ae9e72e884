"""Each finding check, on small real series: real C sources in real git repositories, measured
stage by stage by the real pipeline; one series the thesis's words describe, one they do not."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import pytest

from archmetrics.app.diff_options import DiffRequest
from archmetrics.app.series import SeriesRequest, run_compare
from archmetrics.config import Settings
from archmetrics.reports.model import CompareReport, SeriesReport
from archmetrics.study.findings import FINDINGS, Finding, check_findings, summary
from tests.gitrepo import GitRepo

STAGES = ("baseline", "first", "second")
Unit = tuple[str, int, int, tuple[str, ...]]  # name, plain statements, ifs, calls
Stage = Mapping[str, str]


def unit(name: str, plain: int = 0, ifs: int = 0, calls: Sequence[str] = ()) -> Unit:
    return (name, plain, ifs, tuple(calls))


def c_file(units: Sequence[Unit], includes: Sequence[str] = ("sys/socket.h",)) -> str:
    """A C file: 1 + plain + 2·ifs + calls + 1 statements and ifs + 1 paths per function."""
    text = "".join(f"#include <{name}>\n" for name in includes) + "\n"
    for name, plain, ifs, calls in units:
        body = "".join(f"  v = v + {i};\n" for i in range(plain))
        body += "".join(f"  if (v > {i})\n    v = v - 1;\n" for i in range(ifs))
        body += "".join(f"  {call};\n" for call in calls)
        text += f"int {name}(int v, int fd)\n{{\n{body}  return v;\n}}\n\n"
    return text


CORE = unit("core", 20, 5)  # 32 statements, v_g 6: E = 5.33 at the baseline
CLIENT = unit("main", 3)
SEND, RECV, ACCEPT = "send(fd, 0, 0, 0)", "recv(fd, 0, 0, 0)", "accept(fd, 0, 0)"


def grown(*later: Unit, core: Unit = CORE, client: Unit = CLIENT) -> list[Stage]:
    """Baseline: ``core`` in the framework and a client; each later stage adds one unit."""
    return [
        {"fw/glue.c": c_file([core, *later[:n]]), "app/client.c": c_file([client])}
        for n in range(len(STAGES))
    ]


def request(root: Path, stages: Sequence[Stage]) -> SeriesRequest:
    """A repository with one commit and tag per stage: ``fw/`` framework, ``new/`` new."""
    repo = GitRepo(root)
    for label, files in zip(STAGES, stages, strict=True):
        repo.commit(label, tag=label, files=files)
    diff = DiffRequest(root, "", "", Settings(), new=("new/**",), framework=("fw/**",))
    return SeriesRequest(diff, STAGES, STAGES)


Study = Callable[..., dict[str, SeriesReport]]


@pytest.fixture
def study(tmp_path: Path) -> Study:
    """Approach name -> its stages, measured together by run_compare."""

    runs = iter(range(1_000))

    def measure(**approaches: Sequence[Stage]) -> dict[str, SeriesReport]:
        where = tmp_path / f"run{next(runs)}"
        named = [(name, request(where / name, stages)) for name, stages in approaches.items()]
        return dict(run_compare(named).series)

    return measure


def finding(id_: str) -> Finding:
    return next(f for f in FINDINGS if f.id == id_)


def verdict(id_: str, found: Mapping[str, SeriesReport]) -> bool | None:
    return finding(id_).check(found).agrees


# -- World Database --------------------------------------------------------------------------


def test_wdb_soa_coupling(study: Study) -> None:
    plain = study(soa=grown(unit("op1", 2), unit("op2", 2)))
    assert verdict("wdb-soa-coupling", plain) is True
    stages = grown(unit("op1", 2), unit("op2", 2))
    stages[1] = {**stages[1], "fw/glue.c": c_file([CORE, unit("op1", 2)], ("sys/socket.h", "x.h"))}
    stages[2] = {**stages[2], "fw/glue.c": c_file([CORE, unit("op1", 2), unit("op2", 2)])}
    included = study(soa=stages)
    assert summary(included["soa"], "first").delta_s_e == 1
    assert verdict("wdb-soa-coupling", included) is False


def test_wdb_soa_cost_needs_no_new_path(study: Study) -> None:
    lines = [{"fw/glue.c": c_file([unit("core", 20 + n, 5)])} for n in range(3)]
    found = study(soa=lines)
    assert summary(found["soa"], "second", "framework").changes == 1
    assert verdict("wdb-soa-cost", found) is True
    branches = [{"fw/glue.c": c_file([unit("core", 20, 5 + n)])} for n in range(3)]
    assert verdict("wdb-soa-cost", study(soa=branches)) is False
    # "a high complexity change cost in the initial creation of the baseline" (p. 120)
    empty = [{"fw/glue.c": "", "app/client.c": ""}] * 3
    assert verdict("wdb-soa-cost", study(soa=empty)) is False


def test_wdb_player_coupling_one_include_and_two_links_a_message(study: Study) -> None:
    headers = (("sys/socket.h",), ("sys/socket.h", "a.h"), ("sys/socket.h", "a.h", "b.h"))
    units = [CORE, unit("op1", 1, 0, [SEND, SEND]), unit("op2", 1, 0, [SEND, SEND])]
    stages = [{"fw/glue.c": c_file(units[: n + 1], headers[n])} for n in range(3)]
    found = study(player=stages)
    assert [summary(found["player"], s).delta_d_e for s in STAGES[1:]] == [2, 2]
    assert verdict("wdb-player-coupling", found) is True
    one_link = study(player=grown(unit("op1", 1, 0, [SEND]), unit("op2", 1, 0, [SEND])))
    assert verdict("wdb-player-coupling", one_link) is False


def test_wdb_player_growth_thirty_to_forty_lines_near_six_paths(study: Study) -> None:
    big = unit("core", 60, 40)  # v_g 41, so the scale factors stay near 1
    found = study(player=grown(unit("op1", 20, 5), unit("op2", 20, 5), core=big))
    first = summary(found["player"], "first")
    assert (first.changes, first.delta_vg) == (32, 6)
    assert verdict("wdb-player-growth", found) is True
    small = study(player=grown(unit("op1", 5, 1), unit("op2", 5, 1), core=big))
    assert verdict("wdb-player-growth", small) is False


def test_wdb_p2p_coupling_accept_send_recv_a_message(study: Study) -> None:
    trio = [ACCEPT, SEND, RECV]
    found = study(p2p=grown(unit("op1", 1, 0, trio), unit("op2", 1, 0, trio)))
    assert verdict("wdb-p2p-coupling", found) is True
    shared = study(p2p=grown(unit("op1", 1), unit("op2", 1)))
    assert verdict("wdb-p2p-coupling", shared) is False


def test_wdb_p2p_growth_largest_at_every_later_stage(study: Study) -> None:
    found = study(
        p2p=grown(unit("op1", 30, 6), unit("op2", 30, 6)), soa=grown(unit("op1", 3), unit("op2", 3))
    )
    assert verdict("wdb-p2p-growth", found) is True
    tabled = study(
        p2p=grown(unit("op1", 30, 6), unit("op2", 1)), soa=grown(unit("op1", 3), unit("op2", 3))
    )
    assert verdict("wdb-p2p-growth", tabled) is False
    assert verdict("wdb-p2p-growth", {"p2p": tabled["p2p"]}) is None


# -- Pragmatics and the legacy driver --------------------------------------------------------


def test_prag_soa_coupling_relatively_large_dynamic_efferent(study: Study) -> None:
    two, one = [SEND, SEND], [SEND]
    found = study(
        soa=grown(unit("op1", 1, 0, two), unit("op2", 1, 0, two)),
        player=grown(unit("op1", 1, 0, one), unit("op2", 1, 0, one)),
    )
    assert verdict("prag-soa-coupling", found) is True
    reverse = study(
        soa=grown(unit("op1", 1, 0, one), unit("op2", 1, 0, one)),
        player=grown(unit("op1", 1, 0, two), unit("op2", 1, 0, two)),
    )
    assert verdict("prag-soa-coupling", reverse) is False  # below every other approach
    middle = study(
        soa=grown(unit("op1", 1, 0, one), unit("op2", 1, 0, one)),
        player=grown(unit("op1", 1, 0, two), unit("op2", 1, 0, two)),
        p2p=grown(unit("op1", 1), unit("op2", 1)),
    )
    assert verdict("prag-soa-coupling", middle) is True  # "relatively large", not the largest
    flat = grown(unit("op1", 1), unit("op2", 1))
    none = study(soa=flat, p2p=flat)
    assert verdict("prag-soa-coupling", none) is False  # zero is not large


def costs(series: SeriesReport) -> list[float]:
    return [summary(series, stage).cost for stage in STAGES]


def test_prag_soa_cost_large_first_then_relatively_constant(study: Study) -> None:
    found = study(soa=grown(unit("op1", 8, 2), unit("op2", 8, 2)))
    baseline, first, second = costs(found["soa"])
    assert first < baseline and abs(second - first) < 0.1 * first
    assert verdict("prag-soa-cost", found) is True
    apart = study(soa=grown(unit("op1", 8, 2), unit("op2", 30, 1)))
    assert verdict("prag-soa-cost", apart) is False  # the message additions differ
    rising = study(soa=grown(unit("op1", 30, 1), unit("op2", 30, 1)))
    assert verdict("prag-soa-cost", rising) is False  # rises far above the baseline


def test_prag_player_cost_jumps_then_drops(study: Study) -> None:
    found = study(player=grown(unit("op1", 30, 1), unit("op2", 4, 3)))
    assert verdict("prag-player-cost", found) is True
    even = study(player=grown(unit("op1", 8, 2), unit("op2", 8, 2)))
    baseline, first, _ = costs(even["player"])
    assert first < baseline
    assert verdict("prag-player-cost", even) is False
    small = study(player=grown(unit("op1", 12, 2), unit("op2", 4, 3)))
    baseline, first, _ = costs(small["player"])
    assert baseline < first < 1.25 * baseline  # a rise within "near constant" is no jump
    assert verdict("prag-player-cost", small) is False


def test_prag_p2p_cost_rises_and_is_highest(study: Study) -> None:
    soa = grown(unit("op1", 8, 2), unit("op2", 8, 2))
    found = study(p2p=grown(unit("op1", 8, 2), unit("op2", 30, 1)), soa=soa)
    assert verdict("prag-p2p-cost", found) is True
    falling = study(p2p=grown(unit("op1", 8, 2), unit("op2", 4, 3)), soa=soa)
    assert verdict("prag-p2p-cost", falling) is False
    higher = study(p2p=grown(unit("op1", 8, 2), unit("op2", 30, 1)),
                   soa=grown(unit("op1", 8, 2), unit("op2", 40, 1)))  # fmt: skip
    assert verdict("prag-p2p-cost", higher) is False  # rises, but is not the highest


def test_legacy_soa_cost_large_first_then_falls_or_stays_near(study: Study) -> None:
    falling = study(soa=grown(unit("op1", 8, 2), unit("op2", 8, 2)))
    assert verdict("legacy-soa-cost", falling) is True
    dropping = study(soa=grown(unit("op1", 8, 2), unit("op2", 4, 3)))
    assert verdict("legacy-soa-cost", dropping) is True
    near = study(soa=grown(unit("op1", 12, 2), unit("op2", 12, 2)))
    baseline, first, _ = costs(near["soa"])
    assert baseline < first <= 1.25 * baseline  # flat from the start: the initial is not large
    assert verdict("legacy-soa-cost", near) is False
    jump = study(soa=grown(unit("op1", 30, 1), unit("op2", 30, 1)))
    assert verdict("legacy-soa-cost", jump) is False


def test_check_findings_reads_each_subject_and_marks_missing_ones(study: Study) -> None:
    found = study(soa=grown(unit("op1", 2), unit("op2", 2)))
    outcomes = {o.finding.id: o.verdict for o in check_findings({"wdb": CompareReport(
        tuple(found.items()))})}  # fmt: skip
    assert outcomes["wdb-soa-coupling"].agrees is True
    assert outcomes["wdb-player-coupling"].agrees is None  # no player approach measured
    assert outcomes["prag-soa-cost"].agrees is None  # no pragmatics subject
    assert "not measured" in outcomes["prag-soa-cost"].measured
