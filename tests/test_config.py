"""Configuration files: defaults, both file forms, and errors that name the file and key."""

from __future__ import annotations

from pathlib import Path

import pytest

from archmetrics.config import ConfigError, Settings, load_settings


def test_defaults_without_a_file(tmp_path: Path) -> None:
    assert load_settings(tmp_path) == Settings()


def test_pyproject_table(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text(
        '[tool.archmetrics]\nlanguages = { ".h" = "c" }\nexclude = ["vendor/**"]\n'
        '[tool.archmetrics.locations]\nnew = ["wdb/**"]\n'
        "[tool.archmetrics.coupling]\nper-file = true\n"
    )
    settings = load_settings(tmp_path)
    assert settings.languages == ((".h", "c"),)
    assert settings.exclude == ("vendor/**",)
    assert settings.locations.new == ("wdb/**",)
    assert settings.coupling.per_file is True
    assert settings.coupling.ignore_includes == ("stdio.h", "stdlib.h")


def test_archmetrics_toml_wins_over_pyproject(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text('[tool.archmetrics]\nexclude = ["a"]\n')
    (tmp_path / "archmetrics.toml").write_text('exclude = ["b"]\n')
    assert load_settings(tmp_path).exclude == ("b",)


def test_pyproject_without_table_gives_defaults(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "x"\n')
    assert load_settings(tmp_path) == Settings()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('exclud = ["a"]\n', "unknown key 'exclud'"),
        ('exclude = "a"\n', "exclude: expected a list of strings"),
        ("[locations]\nnewer = []\n", "unknown key 'newer'"),
        ("jobs = -1\n", "jobs: expected a non-negative integer"),
        ("exclude = [\n", "not valid TOML"),
        ("[macros]\nexport = []\n", "unknown key 'export'"),
        ('[macros]\nattribute = "A"\n', "macros.attribute: expected a list of strings"),
        ('[macros]\nfunction = ["TEST(x)"]\n', "'TEST\\(x\\)' is not a C identifier"),
        ('[macros]\nattribute = ["' + "A" * 201 + '"]\n', "at most 200 characters"),
    ],
)
def test_errors_name_file_and_key(tmp_path: Path, text: str, message: str) -> None:
    (tmp_path / "archmetrics.toml").write_text(text)
    with pytest.raises(ConfigError, match=message) as error:
        load_settings(tmp_path)
    assert "archmetrics.toml" in str(error.value)


def test_macros_are_read_sorted_without_repeats(tmp_path: Path) -> None:
    (tmp_path / "archmetrics.toml").write_text(
        '[macros]\nattribute = ["my_export", "B_API", "my_export"]\nfunction = ["TEST"]\n'
    )
    settings = load_settings(tmp_path)
    assert settings.macros.attribute == ("B_API", "my_export")
    assert settings.macros.function == ("TEST",)


def test_both_configurations_say_which_is_read_and_a_near_miss_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from archmetrics.cli import main

    (tmp_path / "archmetrics.toml").write_text('gates = ["changes > 1"]\n')
    (tmp_path / "pyproject.toml").write_text(
        '[tool.archmetrics]\ngates = ["changes > 2"]\n\n[tool.archmetric]\njobs = 1\n'
    )
    (tmp_path / "a.py").write_text("x = 1\n")
    settings = load_settings(tmp_path)
    assert settings.gates == ("changes > 1",) and settings.gate_lines == (1,)
    assert main(["scan", str(tmp_path), "-q", "--no-cache", "-v"]) == 0
    err = capsys.readouterr().err
    assert (
        f"warning: {tmp_path / 'archmetrics.toml'} and [tool.archmetrics] in "
        f"{tmp_path / 'pyproject.toml'} both configure archmetrics: archmetrics.toml is read"
    ) in err
    assert "[tool.archmetric] is not read by archmetrics: did you mean [tool.archmetrics]?" in err
    assert f"archmetrics: configuration: {tmp_path / 'archmetrics.toml'}" in err
