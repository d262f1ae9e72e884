"""Descriptor files from strangers: no DTDs or entities, bounded size, one-line errors."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from robosoa.descriptor import DescriptorError, load, loads
from robosoa.descriptor.loader import MAX_DESCRIPTOR_BYTES
from tests.robosoa.procs import PYTHON, REPO, _env

BODY = """<service name="x" version="1.0.0"><definition>{text}</definition>
<pattern>request-response</pattern><operation name="op"/></service>
"""

DTDS = {
    "internal entity": '<!DOCTYPE service [<!ENTITY e "hello">]>',
    "external entity": '<!DOCTYPE service [<!ENTITY e SYSTEM "file:///etc/passwd">]>',
    "parameter entity": '<!DOCTYPE service [<!ENTITY % p SYSTEM "http://127.0.0.1:9/x"> %p;]>',
    "external DTD": '<!DOCTYPE service SYSTEM "http://127.0.0.1:9/x.dtd">',
    "billion laughs": '<!DOCTYPE service [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;">]>',
    "lower case": '<!doctype service [<!entity e "x">]>',
}


def validate(path: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([PYTHON, "-m", "robosoa", "validate", str(path), *extra],
                          capture_output=True, text=True, env=_env(), cwd=REPO, timeout=60)


@pytest.mark.parametrize("kind", sorted(DTDS))
def test_dtds_and_entities_are_refused_naming_the_line(kind: str, tmp_path: Path) -> None:
    text = f'<?xml version="1.0"?>\n{DTDS[kind]}\n' + BODY.format(text="&e; &b;")
    with pytest.raises(DescriptorError) as caught:
        loads(text, source="evil.xml")
    assert [str(p) for p in caught.value.problems] == [
        "evil.xml:2: DTDs and entity declarations are not allowed"]
    path = tmp_path / "evil.xml"
    path.write_text(text)
    done = validate(path)
    assert done.returncode == 2
    assert done.stderr == f"{path}:2: DTDs and entity declarations are not allowed\n"


def test_an_undefined_entity_reference_is_a_syntax_error() -> None:
    with pytest.raises(DescriptorError, match=r"x.xml:1: not well-formed XML: .*Entity 'e'"):
        loads(BODY.format(text="&e;"), source="x.xml")


def test_descriptor_size_is_bounded(tmp_path: Path) -> None:
    text = BODY.format(text="x" * 2000)
    assert loads(text, max_bytes=len(text.encode())).name == "x"
    with pytest.raises(DescriptorError, match="larger than 1999 bytes"):
        loads(text, max_bytes=1999)
    big = tmp_path / "big.xml"
    big.write_text(BODY.format(text="x" * MAX_DESCRIPTOR_BYTES))
    with pytest.raises(DescriptorError, match=f"larger than {MAX_DESCRIPTOR_BYTES} bytes"):
        load(big)
    done = validate(big)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert "Traceback" not in done.stderr
    small = tmp_path / "small.xml"
    small.write_text(text)
    size = len(text.encode())
    assert validate(small, "--max-size", str(size)).returncode == 0
    done = validate(small, "--max-size", str(size - 1))
    assert (done.returncode, done.stderr.count("\n")) == (2, 1)
    assert f"larger than {size - 1} bytes" in done.stderr


def test_only_regular_files_are_read(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.xml"
    os.mkfifo(fifo)  # opening it would block until a writer came: never opened
    for path in (fifo, tmp_path, Path("/dev/zero")):
        with pytest.raises(DescriptorError, match="not a regular file"):
            load(path)


def test_text_that_is_not_utf8_is_refused_in_one_line(tmp_path: Path) -> None:
    path = tmp_path / "latin.xml"
    path.write_bytes(BODY.format(text="caf\xe9").encode("latin-1"))
    done = validate(path)
    assert done.returncode == 2 and "cannot read" in done.stderr
    assert done.stderr.count("\n") == 1
    with pytest.raises(DescriptorError, match="cannot be encoded as UTF-8"):
        loads(BODY.format(text="\ud800"))


def test_problems_print_on_one_line_whatever_the_file_name() -> None:
    with pytest.raises(DescriptorError) as caught:
        loads(BODY.format(text="x").replace('name="x"', 'name="None"'), source="a\nb\u2028.xml")
    for problem in caught.value.problems:
        assert len(str(problem).splitlines()) == 1
        assert str(problem).startswith("a\\nb\\u2028.xml:1: ")
