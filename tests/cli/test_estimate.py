"""`archmetrics estimate` end to end on real repositories.

The plan's architecture ``planned`` states exactly what the sketch commit does to the base
(8 statements added, 1 modified, a function with one decision, two imports, a connect and a
send to the server's port); its estimate must equal the measured diff, and so must the same
change given as a revision, a patch and a folder of stubs.
"""

from __future__ import annotations

import json
import textwrap
from pathlib import Path
from typing import Any

import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo
from tests.reports.test_charts import svg_texts

SERVER = """\
import socket

PORT = 5555


def serve():
    s = socket.socket()
    s.bind(("", PORT))
    s.listen(1)
    conn, _ = s.accept()
    data = conn.recv(1024)
    return data
"""
MAIN_V1 = """\
def run(n):
    total = 0
    for i in range(n):
        total = total + i
    return total
"""
MAIN_V2 = """\
import socket

from wdb import store


def run(n):
    total = 0
    for i in range(n):
        total = total + i * 2
    return total


def report(total):
    if total > 10:
        s = socket.socket()
        s.connect(("localhost", 5555))
        s.send(b"big")
    return store.put({}, "total", total)
"""
STORE = "def put(db, key, value):\n    db[key] = value\n    return db\n"
EXACT = """\
[[architecture.planned.element]]
name = "app/main.py"
statements_added = 8
statements_modified = 1
functions_added = 1
decisions_added = 1
static_dependencies = ["socket", "wdb/store.py"]
dynamic_links = [
  { rule = "posix-sockets/py-connect", to = "app/server.py" },
  { rule = "posix-sockets/py-send", to = "app/server.py" },
]
"""
NUMBERS = (
    "delta_s_a",
    "delta_s_e",
    "delta_d_a",
    "delta_d_e",
    "loc_pre",
    "loc_post",
    "loc_scale",
    "added",
    "removed",
    "modified",
    "changes",
    "scaled_changes",
    "vg_pre",
    "vg_post",
    "vg_scale",
    "delta_vg",
    "scaled_delta_vg",
    "cost",
)


@pytest.fixture
def sketched(repo: GitRepo) -> GitRepo:
    """``base``: a server, a loop, a store; ``sketch``: the loop's client reports to both."""
    files = {"app/server.py": SERVER, "app/main.py": MAIN_V1, "wdb/store.py": STORE}
    repo.commit("base", tag="base", files=files)
    repo.git("checkout", "-q", "-b", "sketch")
    repo.commit("sketch", tag="sketch", files={"app/main.py": MAIN_V2})
    repo.git("checkout", "-q", "main")
    return repo


def write_plan(folder: Path, text: str, name: str = "plan.toml") -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def run(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], *argv: str, status: int = 0
) -> tuple[str, str]:
    code = main(["estimate", "-C", str(repo.root), "--new", "wdb/**", *argv])
    out, err = capsys.readouterr()
    assert code == status, err
    return out, err


def estimate(repo: GitRepo, capsys: pytest.CaptureFixture[str], plan: Path, *argv: str) -> Any:
    out, _ = run(repo, capsys, str(plan), "--base", "base", "--format", "json", *argv)
    return json.loads(out)


def measured(repo: GitRepo, capsys: pytest.CaptureFixture[str]) -> Any:
    argv = ["diff", "-C", str(repo.root), "--new", "wdb/**", "--base", "base"]
    assert main([*argv, "--head", "sketch", "--format", "json"]) == 0
    return json.loads(capsys.readouterr()[0])


def numbers(locations: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {name: {f: summary[f] for f in NUMBERS} for name, summary in locations.items()}


def locations_of(document: Any, architecture: str, stage: int = 0) -> dict[str, Any]:
    return document["architectures"][architecture]["stages"][stage]["locations"]  # type: ignore[no-any-return]


def test_a_plan_that_states_what_the_sketch_does_estimates_the_measured_diff(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = write_plan(
        tmp_path, EXACT + '\n[architecture.sketched]\nsketch = { revision = "sketch" }\n'
    )
    document = estimate(sketched, capsys, plan)
    diff = measured(sketched, capsys)
    assert document["schema"] == "archmetrics.estimate/1" and document["estimate"] is True
    assert numbers(locations_of(document, "planned")) == numbers(diff["locations"])
    assert numbers(locations_of(document, "sketched")) == numbers(diff["locations"])
    assert document["architectures"]["planned"]["kind"] == "plan"
    assert document["architectures"]["sketched"]["kind"] == "sketch:revision"
    # per element too: Γ counts and λ, v_g and coupling after
    planned = {
        e["element"]: e for e in document["architectures"]["planned"]["stages"][0]["elements"]
    }
    for element in diff["elements"]:
        mine = planned[element["element"]]
        for field in ("location", "status", "added", "removed", "modified"):
            assert mine[field] == element[field], (element["element"], field)
        for field in ("loc", "vg", "s_a", "s_e", "d_a", "d_e"):
            assert mine["post"][field] == element["post"][field], (element["element"], field)
    notes = locations_of(document, "planned")["total"]["notes"]
    assert any(n.startswith("estimate_from_plan:") for n in notes)


def test_a_patch_and_a_folder_of_stubs_are_measured_as_the_revision_is(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "sketch.patch").write_text(sketched.git("diff", "base", "sketch"), encoding="utf-8")
    stubs = tmp_path / "stubs" / "app"
    stubs.mkdir(parents=True)
    (stubs / "main.py").write_text(MAIN_V2, encoding="utf-8")
    plan = write_plan(
        tmp_path,
        """\
        [architecture.revision]
        sketch = { revision = "sketch" }
        [architecture.patch]
        sketch = { patch = "sketch.patch" }
        [architecture.stubs]
        sketch = { stubs = "stubs" }
        """,
    )
    document = estimate(sketched, capsys, plan)
    revision = numbers(locations_of(document, "revision"))
    assert numbers(locations_of(document, "patch")) == revision
    assert numbers(locations_of(document, "stubs")) == revision
    assert document["architectures"]["patch"]["kind"] == "sketch:patch"
    assert sketched.status() == ""  # the repository is left as it was


def test_the_ranking_puts_the_cheapest_total_cost_first(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = write_plan(
        tmp_path,
        EXACT
        + """
        [[architecture.lean.element]]
        name = "app/main.py"
        statements_added = 2
        functions_added = 1
        """,
    )
    document = estimate(sketched, capsys, plan)
    ranking = [(r["rank"], r["architecture"]) for r in document["ranking"]]
    costs = {n: locations_of(document, n)["total"]["cost"] for n in ("planned", "lean")}
    expected = sorted(costs, key=lambda n: costs[n])
    assert ranking == [(1, expected[0]), (2, expected[1])]
    # lean by hand: λ 17 -> 19, Γ = 2, Vg 4 -> 5: Γ' = 19/17·2, ΔVg' = 5/4·1
    assert costs["lean"] == pytest.approx((19 / 17 * 2) / (5 / 4 * 1))


def test_every_format_shows_each_architecture_and_says_it_is_an_estimate(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = write_plan(
        tmp_path, EXACT + '\n[architecture.sketched]\nsketch = { revision = "sketch" }\n'
    )
    table, _ = run(sketched, capsys, str(plan), "--base", "base")
    assert "estimate" in table and "planned total" in table and "sketched total" in table
    assert "ranking" in table
    markdown, _ = run(sketched, capsys, str(plan), "--base", "base", "--format", "markdown")
    assert "estimate, not a measurement" in markdown and "| planned base |" in markdown
    csv, _ = run(sketched, capsys, str(plan), "--base", "base", "--format", "csv")
    header, *rows = csv.splitlines()
    assert header.startswith("architecture,stage,row,name,location")
    assert {r.split(",")[0] for r in rows} == {"planned", "sketched"}


def test_a_gate_fails_on_the_architecture_that_exceeds_it(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = write_plan(
        tmp_path,
        EXACT + '\n[[architecture.tiny.element]]\nname = "wdb/store.py"\nstatements_modified = 1\n',
    )
    argv = [str(plan), "--base", "base", "--fail-on", "changes > 5", "--format", "json"]
    out, err = run(sketched, capsys, *argv, status=1)
    assert json.loads(out)["failures"] == [
        {"architecture": "planned", "stage": "estimate", "gate": "changes > 5"}
    ]
    assert "planned (estimate): gate failed: changes > 5 (changes(total) = 9)" in err
    codeclimate, _ = run(sketched, capsys, str(plan), "--base", "base", "--fail-on", "changes > 5",
                         "--format", "codeclimate", status=1)  # fmt: skip
    assert [i["description"].split(":")[0] for i in json.loads(codeclimate)] == ["planned estimate"]
    sarif, _ = run(sketched, capsys, str(plan), "--base", "base", "--fail-on", "changes > 5",
                   "--format", "sarif", status=1)  # fmt: skip
    [result] = json.loads(sarif)["runs"][0]["results"]
    assert result["ruleId"] == "changes > 5" and result["message"]["text"].startswith("planned")


BAD_PLANS = [
    (
        '[[architecture.a.element]]\nname = "app/nope.py"\nstatements_added = 1\n',
        "architecture.a.element[0].name: unknown element 'app/nope.py'",
    ),
    (
        '[[architecture.a.element]]\nname = "app/main.py"\nstatements_added = -3\n',
        "architecture.a.element[0].statements_added: must be an integer >= 0",
    ),
    (
        '[[architecture.a.element]]\nname = "app/main.py"\n'
        'dynamic_links = [{ rule = "carrier-pigeon" }]\n',
        "architecture.a.element[0].dynamic_links[0].rule: unknown rule 'carrier-pigeon'",
    ),
    (
        '[[architecture.a.element]]\nname = "app/main.py"\nlocation = "moon"\n',
        "architecture.a.element[0].location: unknown location 'moon'",
    ),
    ('[architecture.a\nname = "x"\n', "not valid TOML"),
    (
        '[[architecture.a.element]]\nname = "app/main.py"\n'
        '[[architecture.a.element]]\nname = "app/main.py"\n',
        "architecture.a.element[1].name: element 'app/main.py' is also architecture.a.element[0]",
    ),
    (
        '[[architecture.a.element]]\nname = "app/main.py"\n'
        'dynamic_links = [{ rule = "posix-sockets/py-recv", to = "app/server.py" }]\n',
        "architecture.a.element[0].dynamic_links[0].to: rule 'posix-sockets/py-recv' has role",
    ),
    (
        '[[architecture.a.element]]\nname = "app/main.py"\nstatements_removed = 6\n',
        "architecture.a.element[0].statements_removed: removes and modifies 6 statements",
    ),
    (
        '[[architecture.a.element]]\nname = "app/new.py"\nnew = true\n'
        'static_dependencies = ["app/missing.py"]\n'
        '[[architecture.a.element]]\nname = "app/main.py"\n'
        'dynamic_links = [{ rule = "posix-sockets/py-send", to = "app/ghost.py" }]\n',
        "architecture.a.element[1].dynamic_links[0].to: unknown element 'app/ghost.py'",
    ),
    (
        '[[architecture.a.element]]\nname = "app/main.py"\nnew = true\n',
        "architecture.a.element[0].name: element 'app/main.py' already exists",
    ),
    (
        '[architecture.a]\nsketch = { patch = "../../etc/passwd" }\n',
        "architecture.a.sketch.patch: must be a path inside",
    ),
    (
        '[architecture.a]\nsketch = { revision = "no-such-rev" }\n',
        "architecture.a.sketch.revision: unknown revision",
    ),
    (
        '[[architecture.a.element]]\nname = "app/main.py"\nlines = 3\n',
        "architecture.a.element[0].lines: unknown key",
    ),
]


@pytest.mark.parametrize(("text", "expected"), BAD_PLANS)
def test_a_bad_plan_is_a_one_line_error_naming_the_file_and_the_key(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, expected: str
) -> None:
    plan = tmp_path / "sub" / "bad.toml"
    plan.parent.mkdir()
    plan.write_text(text, encoding="utf-8")
    out, err = run(sketched, capsys, str(plan), "--base", "base", status=2)
    assert out == ""
    assert err.count("\n") == 1
    assert err.startswith(f"archmetrics: error: {plan}: ")
    assert expected in err


def test_a_plan_file_too_large_or_missing_is_refused_before_any_work(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * 1_000_001)
    _, err = run(sketched, capsys, str(big), status=2)
    assert f"{big}: a plan may hold at most 1000000 bytes" in err
    _, err = run(sketched, capsys, str(tmp_path / "none.toml"), status=2)
    assert f"{tmp_path / 'none.toml'}: cannot read" in err


GUESS = """\
[[architecture.guess.element]]
name = "app/main.py"
statements_added = 6
statements_modified = 2
functions_added = 1
decisions_added = 1
static_dependencies = ["wdb/store.py"]
dynamic_links = [{ rule = "posix-sockets/py-connect", to = "app/server.py" }]
"""


def test_actual_reports_the_error_of_every_figure_computed_by_hand(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = write_plan(tmp_path, GUESS)
    argv = ["--actual", "--head", "sketch"]
    document = estimate(sketched, capsys, plan, *argv)
    assert document["actual"]["head"] == "sketch"
    base = document["accuracy"]["guess"]["locations"]["base"]
    # the base location holds main.py (λ 5, v_g 2) and server.py (λ 9, v_g 1): λ_pre 14, Vg 3
    # estimated: Γ = 6 + 2 = 8, λ_post 20; measured: Γ = 8 + 1 = 9, λ_post 22; Vg 3 -> 5 both
    assert base["changes"] == {"estimated": 8, "actual": 9, "error": -1, "relative": -1 / 9}
    assert base["loc_post"]["error"] == -2
    assert base["delta_vg"] == {"estimated": 2, "actual": 2, "error": 0, "relative": 0.0}
    estimated_cost = (8 * 20 / 14) / (2 * 5 / 3)
    actual_cost = (9 * 22 / 14) / (2 * 5 / 3)
    assert base["cost"]["estimated"] == pytest.approx(estimated_cost)
    assert base["cost"]["actual"] == pytest.approx(actual_cost)
    assert base["cost"]["error"] == pytest.approx(estimated_cost - actual_cost)
    assert base["cost"]["relative"] == pytest.approx((estimated_cost - actual_cost) / actual_cost)
    # one link and one import planned, two of each made: Δs_e, Δd_e and the server's Δd_a
    for figure in ("delta_s_e", "delta_d_a", "delta_d_e"):
        assert (base[figure]["estimated"], base[figure]["actual"]) == (1, 2), figure
    elements = {e["element"]: e["figures"] for e in document["accuracy"]["guess"]["elements"]}
    main_py = elements["app/main.py"]
    errors = {f: main_py[f]["error"] for f in ("added", "modified", "loc", "vg", "s_e", "d_e")}
    assert errors == {"added": -2, "modified": 1, "loc": -2, "vg": 0, "s_e": -1, "d_e": -1}
    # the server did not change, but the estimate got its d_a wrong: it is listed too
    assert elements["app/server.py"]["d_a"] == {
        "estimated": 1,
        "actual": 2,
        "error": -1,
        "relative": -0.5,
    }
    assert "wdb/store.py" not in elements  # s_a 0 -> 1 on both sides: right
    csv, _ = run(sketched, capsys, str(plan), "--base", "base", *argv, "--format", "csv")
    assert "guess,location,base,base,changes,8,9,-1,-0.111" in csv
    table, _ = run(sketched, capsys, str(plan), "--base", "base", *argv)
    assert "accuracy: the estimate against the measured base → sketch" in table


def test_actual_compares_the_stage_named_and_wants_a_head(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = write_plan(
        tmp_path,
        """\
        [[architecture.a.stage]]
        label = "first"
        [[architecture.a.stage.element]]
        name = "app/main.py"
        statements_added = 100
        [[architecture.a.stage]]
        label = "second"
        [[architecture.a.stage.element]]
        name = "app/main.py"
        statements_added = 8
        statements_modified = 1
        """,
    )
    _, err = run(sketched, capsys, str(plan), "--actual", "--head", "sketch", status=2)
    assert f"{plan}: architecture.a: has stages first, second: --stage names the one" in err
    _, err = run(sketched, capsys, str(plan), "--head", "sketch", status=2)
    assert "--head and --stage go with --actual" in err
    _, err = run(sketched, capsys, str(plan), "--actual", status=2)
    assert "--actual needs --head" in err
    argv = ["--actual", "--head", "sketch", "--stage", "second"]
    document = estimate(sketched, capsys, plan, *argv)
    # the second stage alone, estimated from --base: its Γ is the measured one
    (stage,) = document["architectures"]["a"]["stages"]
    assert stage["label"] == "second"
    assert document["accuracy"]["a"]["locations"]["total"]["changes"]["error"] == 0


def test_a_staged_plan_gives_the_series_each_stage_on_the_one_before(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = write_plan(
        tmp_path,
        """\
        [[architecture.planned.stage]]
        label = "first"
        [[architecture.planned.stage.element]]
        name = "wdb/query.py"
        new = true
        statements_added = 10
        functions_added = 2
        [[architecture.planned.stage]]
        label = "second"
        [[architecture.planned.stage.element]]
        name = "wdb/query.py"
        statements_added = 5
        decisions_added = 2

        [[architecture.drawn.stage]]
        label = "first"
        sketch = { revision = "base" }
        [[architecture.drawn.stage]]
        label = "second"
        sketch = { revision = "sketch" }
        """,
    )
    document = estimate(sketched, capsys, plan)
    planned = document["architectures"]["planned"]["stages"]
    assert [s["label"] for s in planned] == ["first", "second"]
    new = planned[1]["locations"]["new"]
    # wdb: store (λ 3, v_g 1) and the query planned in stage one (λ 10, v_g 2)
    assert (new["loc_pre"], new["loc_post"], new["vg_pre"], new["vg_post"]) == (13, 18, 3, 5)
    assert new["cost"] == pytest.approx((18 / 13 * 5) / (5 / 3 * 2))
    drawn = document["architectures"]["drawn"]["stages"]
    assert drawn[0]["locations"]["total"]["changes"] == 0  # base against itself
    assert numbers(drawn[1]["locations"]) == numbers(measured(sketched, capsys)["locations"])
    ranks = {(r["stage"], r["architecture"]) for r in document["ranking"]}
    assert ranks == {(s, a) for s in ("first", "second") for a in ("planned", "drawn")}
    # the series chart the study draws: one series per architecture over the plan's stages
    chart = tmp_path / "stages.svg"
    run(sketched, capsys, str(plan), "--base", "base", "--chart", str(chart), "-q")
    texts = svg_texts(chart.read_bytes())
    assert {"first", "second", "planned (estimate)", "drawn (estimate)"} <= set(texts), texts
    mixed = write_plan(
        tmp_path,
        """\
        [[architecture.m.stage]]
        label = "first"
        sketch = { revision = "sketch" }
        [[architecture.m.stage]]
        label = "second"
        element = []
        """,
        "mixed.toml",
    )
    _, err = run(sketched, capsys, str(mixed), "--base", "base", status=2)
    assert "architecture.m: mixes planned and sketched stages" in err


def test_an_architecture_may_start_from_its_own_base_and_be_chosen_alone(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = write_plan(
        tmp_path,
        """\
        [architecture.later]
        base = "sketch"
        [[architecture.later.element]]
        name = "app/main.py"
        statements_added = 1
        [[architecture.now.element]]
        name = "app/main.py"
        statements_added = 1
        """,
    )
    document = estimate(sketched, capsys, plan)
    later = document["architectures"]["later"]["stages"][0]
    now = document["architectures"]["now"]["stages"][0]
    assert (later["base"], now["base"]) == ("sketch", "base")
    assert later["locations"]["base"]["loc_pre"] == 22  # main.py 13 + server.py 9 at sketch
    assert now["locations"]["base"]["loc_pre"] == 14
    alone = estimate(sketched, capsys, plan, "--architecture", "now")
    assert list(alone["architectures"]) == ["now"]
    _, err = run(sketched, capsys, str(plan), "--architecture", "never", status=2)
    assert f"{plan}: no architecture 'never' (the plan has later, now)" in err
    bad = write_plan(tmp_path, '[architecture.x]\nbase = "nowhere"\nelement = []\n', "bad.toml")
    _, err = run(sketched, capsys, str(bad), "--base", "base", status=2)
    assert f"{bad}: architecture.x.base: unknown revision 'nowhere'" in err


@pytest.mark.security
def test_a_sketch_cannot_reach_outside_its_tree(
    sketched: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    outside = tmp_path / "secret.py"
    outside.write_text("def leaked():\n    return 1\n", encoding="utf-8")
    (tmp_path / "up.patch").write_text(
        "diff --git a/../../x.py b/../../x.py\nnew file mode 100644\n--- /dev/null\n"
        "+++ b/../../x.py\n@@ -0,0 +1 @@\n+x = 1\n",
        encoding="utf-8",
    )
    plan = write_plan(tmp_path, '[architecture.a]\nsketch = { patch = "up.patch" }\n')
    _, err = run(sketched, capsys, str(plan), "--base", "base", status=2)
    assert f"{plan}: architecture.a.sketch.patch: the patch does not apply" in err
    assert not (tmp_path.parent / "x.py").exists()
    stubs = tmp_path / "stubs" / "app"
    stubs.mkdir(parents=True)
    (stubs / "linked.py").symlink_to(outside)  # a stub that is a link is not followed
    (stubs / "real.py").write_text("y = 2\n", encoding="utf-8")
    plan = write_plan(tmp_path, '[architecture.a]\nsketch = { stubs = "stubs" }\n', "s.toml")
    document = estimate(sketched, capsys, plan)
    files = {e["element"] for e in document["architectures"]["a"]["stages"][0]["elements"]}
    assert "app/real.py" in files and "app/linked.py" not in files
