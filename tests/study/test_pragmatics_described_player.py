"""The MURI Pragmatics subject on Player as the thesis describes it (Hestand 2011, pp. 127,
132-135): the nine packages wired with no messages at the baseline, the messages entering the
GUI, Pragmatics and Backend interfaces at the first stage, one more message at the second.

Player cannot be installed: every C/C++ file of every stage is compiled syntax-only against the
Player stand-in header, as for the idiomatic subject.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from archmetrics.study.manifest import load_manifest
from tests.study.test_pragmatics_subjects import PLAYER_HEADERS, STAND_IN

REPO = Path(__file__).resolve().parents[2]
DESCRIBED = REPO / "fixtures" / "study" / "as-described" / "pragmatics" / "player"
IDIOMATIC = REPO / "fixtures" / "study" / "pragmatics" / "player"
STAGES = ("baseline", "first", "second")
# the messages each interface defines at each stage
MESSAGES = {
    "baseline": {"muriguiinterf": set(), "muripraginterf": set(), "muribackendinterf": set()},
    "first": {"muriguiinterf": {"REPORT"}, "muripraginterf": {"DRIVE"},
              "muribackendinterf": {"TRANSLATE", "STATUS"}},
    "second": {"muriguiinterf": {"REPORT"}, "muripraginterf": {"DRIVE", "TURN"},
               "muribackendinterf": {"TRANSLATE", "ROTATE", "STATUS"}},
}


@pytest.fixture(scope="module")
def player_includes(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An include folder mapping Player's header paths onto the stand-in header."""
    root = tmp_path_factory.mktemp("player-includes")
    for header in PLAYER_HEADERS:
        path = root / header
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f'#include "{STAND_IN}"\n', encoding="utf-8")
    return root


def test_manifest_quotes_a_sentence_and_page_for_every_stage() -> None:
    manifest = load_manifest(DESCRIBED)
    assert (manifest.subject, manifest.variant) == ("pragmatics", "as-described")
    assert [f.stage for f in manifest.follows] == list(STAGES)
    assert not manifest.exclude_generated  # p. 96: the generated plugin headers are counted
    assert ("base", ("clients/**", "pragmatics/**")) in manifest.locations  # p. 127


@pytest.mark.parametrize("stage", STAGES)
def test_messages_enter_every_interface_at_the_first_stage(stage: str) -> None:
    """P. 135: the messages are introduced at the first stage; p. 132: one in each of the GUI,
    Pragmatics and Backend."""
    for name, wanted in MESSAGES[stage].items():
        definition = (DESCRIBED / stage / "interfaces" / name / f"{name}.def").read_text()
        found = set(re.findall(r"message\s*\{\s*(?:CMD|DATA),\s*(\w+),", definition))
        assert found == wanted, name
        driver = (DESCRIBED / stage / "drivers" / f"{name}_driver.cc").read_text()
        assert driver.count("Message::MatchMessage(") == len(wanted)  # one block a message
    # the stages after the baseline are the idiomatic subject's, one stage later
    later = {"first": "baseline", "second": "first"}
    if stage in later:
        for path in (IDIOMATIC / later[stage]).rglob("*"):
            if path.is_file():
                ours = DESCRIBED / stage / path.relative_to(IDIOMATIC / later[stage])
                assert ours.read_bytes() == path.read_bytes(), ours


@pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("g++") is None,
                    reason="needs gcc and g++")
@pytest.mark.parametrize("stage", STAGES)
def test_player_stage_compiles_against_the_player_api(stage: str, player_includes: Path) -> None:
    root = DESCRIBED / stage
    sources = sorted(root.rglob("*.c")) + sorted(root.rglob("*.cc"))
    # 3 proxies, 3 drivers, 3 clients, motion, and the mapping once there are messages
    assert len(sources) == (10 if stage == "baseline" else 11)
    for source in sources:
        compiler = ["g++"] if source.suffix == ".cc" else ["gcc", "-std=c99"]
        done = subprocess.run([*compiler, "-fsyntax-only", "-Wall", "-Wextra", "-Werror",
                               "-I", str(player_includes), str(source)],
                              capture_output=True, text=True, timeout=60)  # fmt: skip
        assert done.returncode == 0, f"{source}:\n{done.stderr}"
