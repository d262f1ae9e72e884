"""Descriptors covering every packaging form and pattern, and helpers to generate and import.

Not a conftest plugin (the name only groups it with the codegen tests): imported explicitly.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType

import robosoa
from robosoa.codegen import generate, write
from robosoa.descriptor import loads

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = Path(robosoa.__file__).parent / "data" / "examples" / "wdb.xml"

INVENTORY = """\
<?xml version="1.0"?>
<service name="inventory" version="2.1.0">
  <definition>Parts inventory with "quotes" and a \\ backslash.</definition>
  <pattern>request-response</pattern>
  <types>
    <struct name="Item">
      <definition>One stocked part.</definition>
      <field name="sku" type="string"/>
      <field name="count" type="int"/>
      <field name="tags" type="list[string]" required="false"/>
      <field name="location" type="Bin" required="false"/>
    </struct>
    <struct name="Bin">
      <field name="row" type="int"/>
      <field name="shelf" type="int" default="1"/>
    </struct>
  </types>
  <operation name="lookup">
    <definition>Parts whose number starts with sku.</definition>
    <param name="sku" type="string" definition="part number prefix"/>
    <param name="limit" type="int" default="10"/>
    <param name="exact" type="bool" default="false"/>
    <return name="items" type="list[Item]"/>
    <return name="total" type="float"/>
  </operation>
  <operation name="store">
    <param name="item" type="Item"/>
    <param name="matrix" type="list[list[float]]" required="false"/>
    <return name="ok" type="bool"/>
  </operation>
  <operation name="reset"/>
  <participant actor="provider" packaging="provider-library" group="stores">
    <implementation form="library" library="inventory_impl">
      <function operation="lookup" symbol="find_parts"/>
    </implementation>
    <naming package="inv_provider"/>
  </participant>
  <participant actor="consumer" packaging="consumer-source">
    <naming package="inv_client" class="Inventory"/>
  </participant>
  <participant actor="consumer" packaging="consumer-no-source">
    <implementation form="library" library="legacy.inv_legacy">
      <function operation="lookup" symbol="find_parts"/>
    </implementation>
  </participant>
  <participant actor="provider" packaging="provider-executable">
    <implementation form="executable" encoding="xml" timeout="20">
      <command>{python} inventory_prog.py</command>
    </implementation>
    <naming package="inv_exec"/>
  </participant>
</service>
"""

CALC = """\
<service name="calc" version="1.0.0">
  <pattern>request-response</pattern>
  <operation name="add">
    <param name="a" type="int"/><param name="b" type="float"/><return name="sum" type="float"/>
  </operation>
  <operation name="greet">
    <param name="name" type="string"/><param name="loud" type="bool" default="false"/>
    <return name="text" type="string"/>
  </operation>
  <operation name="tick"/>
  <operation name="count"><return name="n" type="int"/></operation>
  <participant actor="provider" packaging="provider-library">
    <target language="c" os="posix"/>
    <implementation form="library" library="./libcalc.so">
      <function operation="add" symbol="calc_add"/>
    </implementation>
    <naming package="calc_provider"/>
  </participant>
  <participant actor="consumer" packaging="consumer-source"/>
  <participant actor="provider" packaging="provider-executable">
    <implementation form="executable" encoding="json">
      <command operation="add">{python} calc_prog.py</command>
      <command>{python} -c "import sys; sys.exit('calc: no such program')"</command>
    </implementation>
    <naming package="calc_exec"/>
  </participant>
</service>
"""

SENSOR = """\
<service name="{name}" version="1.0.0">
  <pattern>{pattern}</pattern>
  <types>
    <struct name="Pose"><field name="x" type="float"/><field name="y" type="float"/></struct>
  </types>
  <operation name="reading">
    <qos depth="10" lifespan="30" max-bytes="65536"/>
    <param name="value" type="float"/><param name="unit" type="string" default="m"/>
    <param name="where" type="Pose" required="false"/>
  </operation>
  <operation name="heartbeat"/>
  <participant actor="provider" packaging="provider-library"/>
  <participant actor="consumer" packaging="consumer-source"/>
</service>
"""

CAMERA = """\
<service name="camera" version="1.0.0">
  <pattern>request-response</pattern>
  <types>
    <struct name="Image">
      <field name="pixels" type="bytes"/><field name="width" type="int"/>
    </struct>
  </types>
  <operation name="snap" idempotent="true">
    <param name="mask" type="bytes"/>
    <param name="tiles" type="list[bytes]" required="false"/>
    <return name="image" type="Image"/>
    <return name="thumbs" type="list[bytes]"/>
  </operation>
  <participant actor="provider" packaging="provider-library">
    <implementation form="library" library="camera_impl"/>
  </participant>
  <participant actor="consumer" packaging="consumer-source"/>
  <participant actor="provider" packaging="provider-executable">
    <implementation form="executable" encoding="json">
      <command>{python} camera_prog.py</command>
    </implementation>
    <naming package="camera_exec"/>
  </participant>
</service>
"""

MOTOR = """\
<service name="{name}" version="1.0.0">
  <pattern{delivery}>{pattern}</pattern>
  <operation name="stop"><param name="reason" type="string" required="false"/></operation>
  {returns}
  <participant actor="provider" packaging="provider-library">
    <implementation form="library" library="{name}_impl"/>
    <codegen profile="unchecked"/>
  </participant>
  <participant actor="consumer" packaging="consumer-source">
    <codegen profile="unchecked"/>
  </participant>
</service>
"""


def descriptors() -> dict[str, str]:
    """Name -> descriptor text of every case the codegen tests generate."""
    python = sys.executable
    return {
        "wdb.xml": EXAMPLE.read_text(),
        "inventory.xml": INVENTORY.replace("{python}", python),
        "calc.xml": CALC.replace("{python}", python),
        "camera.xml": CAMERA.replace("{python}", python),
        "sensor.xml": SENSOR.format(name="sensor", pattern="publish-subscribe"),
        "alarm.xml": SENSOR.format(name="alarm", pattern="event"),
        "motor.xml": MOTOR.format(
            name="motor", pattern="one-way", delivery=' delivery="all"', returns=""
        ),
        "arm.xml": MOTOR.format(
            name="arm",
            pattern="point-to-point",
            delivery="",
            returns='<operation name="where"><return name="angle" type="float"/></operation>',
        ),
    }


def generate_all(out: Path) -> list[Path]:
    """Write every case's descriptor and every declared form under ``out``."""
    written: list[Path] = []
    for name, text in descriptors().items():
        (out / name).write_text(text)
        descriptor = loads(text, source=str(out / name))
        written += write(generate(descriptor), out)
    return written


@contextmanager
def importable(directory: Path) -> Iterator[None]:
    """Make generated packages under ``directory`` importable; forget them afterwards."""
    before = set(sys.modules)
    sys.path.insert(0, str(directory))
    importlib.invalidate_caches()
    try:
        yield
    finally:
        sys.path.remove(str(directory))
        for name in set(sys.modules) - before:
            module = sys.modules[name]
            if str(directory) in str(getattr(module, "__file__", "") or ""):
                del sys.modules[name]


def load_module(name: str) -> ModuleType:
    """Import a generated module by dotted name."""
    return importlib.import_module(name)
