"""Generated code running for real: skeletons serve on a bus, proxies call them with types.

Every packaging form: a Python implementation module (provider-library), real programs per
request (provider-executable, xml/json/text encodings), a C shared library compiled here with
``cc`` (provider-library through ctypes), a library API re-exposed (consumer-no-source), and
the tutorial's two processes over ZeroMQ.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robosoa
from robosoa.descriptor import ServiceDescriptor, TypeRef
from tests.robosoa.conftest_codegen import REPO, generate_all, importable, load_module
from tests.robosoa.util import eventually

INVENTORY_IMPL = """
from inv_provider.types import Item, LookupResult

STORED: list[Item] = []


def find_parts(sku: str, limit: int = 10, exact: bool = False) -> LookupResult:
    items = [Item(sku=sku + str(i), count=i, tags=("new",)) for i in range(limit)]
    return LookupResult(items=tuple(items), total=float(len(items)))


def store(item: Item, matrix: tuple[tuple[float, ...], ...] | None = None) -> bool:
    STORED.append(item)
    return item.count > 0


def reset() -> None:
    STORED.clear()
"""

INVENTORY_PROG = """
import os, sys
from lxml import etree
request = etree.fromstring(sys.stdin.buffer.read())
operation = os.environ["ROBOSOA_OPERATION"]
assert request.get("operation") == operation
if operation == "lookup":
    sku, limit = request.findtext("sku"), int(request.findtext("limit"))
    items = "".join(
        f"<item><sku>{sku}{i}</sku><count>{i}</count><tags><item>x</item></tags>"
        f"<location><row>{i}</row><shelf>2</shelf></location></item>"
        for i in range(limit)
    )
    print(f"<result><items>{items}</items><total>{limit}.5</total></result>")
elif operation == "store":
    ok = "true" if request.findtext("item/count") != "0" else "false"
    print(f"<result><ok>{ok}</ok></result>")
"""

CALC_PROG = """
import json, sys
args = json.load(sys.stdin)
json.dump({"sum": args["a"] + args["b"]}, sys.stdout)
"""

CALC_C = r"""
#include <ctype.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

static char buffer[128];
static int64_t ticks = 0;

double calc_add(int64_t a, double b) { return (double)a + b; }

const char *greet(const char *name, bool loud) {
    snprintf(buffer, sizeof buffer, "hello %s", name);
    for (char *c = buffer; loud && *c; c++) *c = (char)toupper((unsigned char)*c);
    return buffer;
}

void tick(void) { ticks++; }

int64_t count(void) { return ticks; }
"""

CAMERA_IMPL = """
from camera_provider.types import Image, SnapResult


def snap(mask: bytes, tiles: tuple[bytes, ...] | None = None) -> SnapResult:
    pixels = bytes(b ^ m for b, m in zip(bytes(range(256)) * 4096, mask * 1048576))
    return SnapResult(image=Image(pixels=pixels, width=1024), thumbs=(tiles or ())[::-1])
"""

CAMERA_PROG = """
import base64, json, sys
args = json.load(sys.stdin)
mask = base64.b64decode(args["mask"])
tiles = [base64.b64decode(t) for t in args.get("tiles", [])]
json.dump({"image": {"pixels": base64.b64encode(mask * 3).decode(), "width": 3},
           "thumbs": [base64.b64encode(t + b"!").decode() for t in tiles]}, sys.stdout)
"""

WDB_QUERY = """
import sys
request = sys.stdin.read()
sys.stdout.write("<result><rows>1</rows><echo>" + request + "</echo></result>")
"""

WDB_UPDATE = """
import sys
sys.stdin.read()
sys.stdout.write("<status>ok</status>")
"""

MOTOR_IMPL = """
STOPS: list[str | None] = []


def stop(reason: str | None = None) -> None:
    STOPS.append(reason)


def where() -> float:
    return 42.5
"""


@pytest.fixture(scope="module")
def out(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    directory = tmp_path_factory.mktemp("run")
    generate_all(directory)
    programs = {
        "inventory_impl.py": INVENTORY_IMPL,
        "inventory_prog.py": INVENTORY_PROG,
        "calc_prog.py": CALC_PROG,
        "camera_impl.py": CAMERA_IMPL,
        "camera_prog.py": CAMERA_PROG,
        "wdb_query.py": WDB_QUERY,
        "wdb_update.py": WDB_UPDATE,
        "motor_impl.py": MOTOR_IMPL,
        "arm_impl.py": MOTOR_IMPL,
    }
    for name, text in programs.items():
        (directory / name).write_text(textwrap.dedent(text))
    with importable(directory):
        yield directory


@pytest.fixture
def buses() -> Iterator[tuple[robosoa.Bus, robosoa.Bus]]:
    """A provider-side and a consumer-side bus on a private in-process bus."""
    url = f"inproc://codegen-{uuid.uuid4().hex[:8]}"
    a, b = robosoa.connect(url), robosoa.connect(url)
    yield a, b
    b.close()
    a.close()


def test_python_library_provider_and_source_consumer(
    out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    provider, consumer = buses
    skeleton = load_module("inv_provider.provider")
    impl = skeleton.InventoryProviderLibrary()
    handle = skeleton.InventoryProvider(impl).provide(provider)
    assert handle.info.group == "stores"
    client_module = load_module("inv_client.client")
    types = load_module("inv_client.types")
    client = client_module.Inventory(consumer)

    found = client.lookup("ab", limit=2)
    assert isinstance(found, types.LookupResult)
    assert found.total == 2.0
    assert found.items == (
        types.Item(sku="ab0", count=0, tags=("new",)),
        types.Item(sku="ab1", count=1, tags=("new",)),
    )

    item = types.Item(sku="x", count=3, location=types.Bin(row=4))
    assert client.store(item, matrix=((1.0, 2.0), ())) == types.StoreResult(ok=True)
    stored = load_module("inventory_impl").STORED[-1]
    assert type(stored).__name__ == "Item" and stored.location.row == 4
    assert stored.location.shelf == 1  # default filled in on the provider side
    client.reset()
    assert load_module("inventory_impl").STORED == []


def test_checked_profile_rejects_bad_payloads_on_both_sides(
    out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    provider, consumer = buses
    skeleton = load_module("inv_provider.provider")
    skeleton.InventoryProvider(skeleton.InventoryProviderLibrary()).provide(provider)
    client = load_module("inv_client.client").Inventory(consumer)
    with pytest.raises(robosoa.InvalidMessage, match="parameter 'limit': expected int"):
        client.lookup("ab", limit="2")
    with pytest.raises(robosoa.RemoteInvalidMessage, match=r"parameter 'item.count': expected"):
        consumer.request("inventory", "store", {"item": {"sku": "x", "count": "3"}})


def test_consumer_without_source_keeps_the_library_api(
    out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    provider, consumer = buses
    skeleton = load_module("inv_provider.provider")
    skeleton.InventoryProvider(skeleton.InventoryProviderLibrary()).provide(provider)
    legacy = load_module("inv_legacy")
    assert sorted(legacy.__all__) == ["bind", "find_parts", "reset", "store"]
    legacy.bind(consumer)
    assert legacy.find_parts("q", limit=1).items[0].sku == "q0"
    types = load_module("inv_legacy.types")
    assert legacy.store(types.Item(sku="z", count=0)) is False
    assert legacy.reset() is None


def test_provider_executable_with_xml_documents(
    out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    provider, consumer = buses
    skeleton = load_module("inv_exec.provider")
    skeleton.InventoryProvider(skeleton.InventoryProviderExecutable(str(out))).provide(provider)
    client = load_module("inv_client.client").Inventory(consumer, timeout=20.0)
    found = client.lookup("p", limit=2)
    assert [i.sku for i in found.items] == ["p0", "p1"]
    assert found.items[1].location is not None and found.items[1].location.shelf == 2
    assert found.items[0].tags == ("x",) and found.total == 2.5
    types = load_module("inv_client.types")
    assert client.store(types.Item(sku="s", count=0)).ok is False


def test_provider_executable_with_json_and_a_failing_program(
    out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    provider, consumer = buses
    skeleton = load_module("calc_exec.provider")
    skeleton.CalcProvider(skeleton.CalcProviderExecutable(str(out))).provide(provider)
    client = load_module("calc_client.client").CalcClient(consumer, timeout=20.0)
    assert client.add(2, 0.5).sum == 2.5
    with pytest.raises(robosoa.RemoteError, match="calc: no such program"):
        client.greet("x")


def test_bytes_travel_typed_through_a_library_and_an_executable(
    out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    provider, consumer = buses
    library = load_module("camera_provider.provider")
    library.CameraProvider(library.CameraProviderLibrary()).provide(provider)
    client = load_module("camera_client.client").CameraClient(consumer)
    found = client.snap(b"\x01", tiles=(b"a", b"\x00\xff"))
    assert found.image.width == 1024 and len(found.image.pixels) == 1024 * 1024
    assert found.image.pixels[:3] == b"\x01\x00\x03" and found.thumbs == (b"\x00\xff", b"a")
    with pytest.raises(robosoa.InvalidMessage, match="parameter 'mask': expected bytes, got str"):
        client.snap("not bytes")
    provider.close()
    program = load_module("camera_exec.provider")
    other = robosoa.connect(consumer.adapter.address)
    try:
        program.CameraProvider(program.CameraProviderExecutable(str(out))).provide(other)
        found = load_module("camera_client.client").CameraClient(consumer, timeout=20.0).snap(
            b"\xfe\x00", tiles=(b"\x80",))
        assert found.image.pixels == b"\xfe\x00" * 3 and found.thumbs == (b"\x80!",)
    finally:
        other.close()


@pytest.fixture(scope="module")
def libcalc(out: Path) -> Path:
    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        pytest.skip("no C compiler")
    source = out / "calc.c"
    source.write_text(CALC_C)
    library = out / "libcalc.so"
    subprocess.run(
        [compiler, "-shared", "-fPIC", "-O1", "-o", str(library), str(source)],
        check=True,
        timeout=60,
        capture_output=True,
    )
    return library


def test_provider_library_in_c_through_ctypes(
    out: Path, libcalc: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    provider, consumer = buses
    skeleton = load_module("calc_provider.provider")
    skeleton.CalcProvider(skeleton.CalcProviderLibrary(str(libcalc))).provide(provider)
    client = load_module("calc_client.client").CalcClient(consumer)
    assert client.add(2, 0.25).sum == 2.25
    assert client.greet("bot").text == "hello bot"
    assert client.greet("bot", loud=True).text == "HELLO BOT"
    client.tick()
    client.tick()
    assert client.count().n == 2


def test_wdb_example_runs_its_query_and_update_programs(
    out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    provider, consumer = buses
    skeleton = load_module("wdb_provider.provider")
    skeleton.WdbProvider(skeleton.WdbProviderExecutable(str(out))).provide(provider)
    client = load_module("wdb_client.client").WdbClient(consumer, timeout=20.0)
    reply = client.query(request="<query table='objects'/>")
    assert type(reply).__name__ == "QueryResult"
    assert reply.result == "<result><rows>1</rows><echo><query table='objects'/></echo></result>"
    assert client.update("<update/>").result == "<status>ok</status>"


@pytest.mark.parametrize("service", ["sensor", "alarm"])
def test_publish_subscribe_and_events_deliver_typed_messages(
    service: str, out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]
) -> None:
    publisher_bus, subscriber_bus = buses
    cap = service.capitalize()
    types = load_module(f"{service}_client.types")
    client = getattr(load_module(f"{service}_client.client"), f"{cap}Client")(subscriber_bus)
    readings: list[Any] = []
    beats: list[bool] = []
    subscriptions = [
        client.on_reading(readings.append),
        client.on_heartbeat(lambda: beats.append(True), qos=robosoa.QoS(keep_latest=True)),
    ]
    assert subscriptions[0].qos == robosoa.QoS(depth=10, lifespan=30.0, max_bytes=65536)
    assert subscriptions[1].qos.keep_latest  # overridden in code
    publisher = getattr(load_module(f"{service}_provider.provider"), f"{cap}Provider")(
        publisher_bus
    )
    verb = "emit" if service == "alarm" else "publish"

    def delivered() -> bool:
        getattr(publisher, f"{verb}_reading")(value=1.5, where=types.Pose(x=1.0, y=2.0))
        getattr(publisher, f"{verb}_heartbeat")()
        return bool(readings and beats)

    eventually(delivered, timeout=10.0, every=0.05)
    assert readings[0] == types.ReadingMessage(value=1.5, unit="m", where=types.Pose(x=1.0, y=2.0))
    for sub in subscriptions:
        sub.close()


def test_one_way_and_point_to_point(out: Path, buses: tuple[robosoa.Bus, robosoa.Bus]) -> None:
    provider, consumer = buses
    motor = load_module("motor_provider.provider")
    motor.MotorProvider(motor.MotorProviderLibrary()).provide(provider)
    assert load_module("motor_client.client").MotorClient(consumer).stop(reason="obstacle") == 1
    stops = load_module("motor_impl").STOPS
    eventually(lambda: stops == ["obstacle"], timeout=10.0)

    arm = load_module("arm_provider.provider")
    arm.ArmProvider(arm.ArmProviderLibrary()).provide(provider)
    arm_client = load_module("arm_client.client").ArmClient(consumer)
    assert arm_client.where().angle == 42.5
    assert arm_client.stop() is None


def _env(out: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(out), str(REPO), env.get("PYTHONPATH", "")])
    return env


@pytest.mark.timeout(120)
def test_tutorial_provider_and_consumer_in_two_processes(out: Path, zmq_url: str) -> None:
    provider = subprocess.Popen(
        [sys.executable, "-m", "wdb_provider.provider", "--bus", zmq_url, "--cwd", str(out)],
        env=_env(out),
        cwd=out,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert provider.stderr is not None
        assert "serving on" in provider.stderr.readline()
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "wdb_client.client",
                "--bus",
                zmq_url,
                "--timeout",
                "20",
                "query",
                "request=<q/>",
            ],
            env=_env(out),
            cwd=out,
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout) == {
            "result": "<result><rows>1</rows><echo><q/></echo></result>"
        }
        bad = subprocess.run(
            [sys.executable, "-m", "wdb_client.client", "--bus", zmq_url, "query", "x=1"],
            env=_env(out),
            cwd=out,
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        assert bad.returncode == 1 and "unexpected keyword argument 'x'" in bad.stderr
    finally:
        provider.terminate()
        assert provider.wait(timeout=30) == 0


def wire(d: ServiceDescriptor, t: TypeRef) -> st.SearchStrategy[Any]:
    """Wire values (JSON-like) of descriptor type ``t``."""
    if t.item is not None:
        return st.lists(wire(d, t.item), max_size=3)
    primitives: dict[str, st.SearchStrategy[Any]] = {
        "int": st.integers(-(2**63), 2**63 - 1),
        "float": st.floats(allow_nan=False, allow_infinity=False),
        "bool": st.booleans(),
        "string": st.text(max_size=8),
    }
    if t.name in primitives:
        return primitives[t.name]
    struct = d.type(t.name)
    assert struct is not None
    required = {f.name: wire(d, f.type) for f in struct.fields if f.required}
    optional = {f.name: wire(d, f.type) for f in struct.fields if not f.required}
    return st.fixed_dictionaries(required, optional=optional)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_struct_payloads_validate_and_round_trip(out: Path, data: st.DataObject) -> None:
    types = load_module("inv_client.types")
    d = types.DESCRIPTOR
    payload = data.draw(wire(d, TypeRef("Item")))
    d.validator()("store", {"item": payload})
    item = types.Item.from_payload(payload)
    expected = {**payload}
    if "location" in expected:
        expected["location"] = {"shelf": 1, **expected["location"]}
    assert item.to_payload() == expected
