"""Static coupling in Python: imports resolved through the package structure."""

from __future__ import annotations

from archmetrics.coupling import CouplingReport, Resolution
from tests.coupling.trees import measure


def _deps(report: CouplingReport, element: str) -> dict[str, tuple[Resolution, str | None]]:
    return {d.name: (d.resolution, d.target_element) for d in report.element(element).dependencies}


def test_relative_imports_resolve_from_the_importing_package() -> None:
    report = measure(
        {
            "pkg/__init__.py": "",
            "pkg/core/__init__.py": "VERSION = 1\n",
            "pkg/core/engine.py": (
                "from . import util\nfrom .util import helper\nfrom .. import shared\n"
                "from ..shared import thing\nfrom . import VERSION\n"
            ),
            "pkg/core/util.py": "def helper(): pass\n",
            "pkg/shared.py": "thing = 1\n",
        }
    )
    assert _deps(report, "pkg/core/engine.py") == {
        ".util": (Resolution.INTERNAL, "pkg/core/util.py"),
        "..shared": (Resolution.INTERNAL, "pkg/shared.py"),
        ".": (Resolution.INTERNAL, "pkg/core/__init__.py"),
    }
    assert report.element("pkg/core/engine.py").s_e == 3
    assert report.element("pkg/core/util.py").s_a == 1


def test_from_package_import_submodule_counts_the_submodule() -> None:
    report = measure(
        {
            "app/__init__.py": "NAME = 'app'\n",
            "app/models.py": "",
            "app/views.py": "",
            "main.py": "from app import models, views\nfrom app import NAME\nimport app.models\n",
        }
    )
    assert _deps(report, "main.py") == {
        "app.models": (Resolution.INTERNAL, "app/models.py"),
        "app.views": (Resolution.INTERNAL, "app/views.py"),
        "app": (Resolution.INTERNAL, "app/__init__.py"),
    }
    assert report.element("main.py").s_e == 3  # import app.models is the same element


def test_src_layout_is_detected() -> None:
    report = measure(
        {
            "src/robot/__init__.py": "",
            "src/robot/drive.py": "from robot.sensors import laser\nimport robot.sensors.laser\n",
            "src/robot/sensors/__init__.py": "",
            "src/robot/sensors/laser.py": "",
            "tests/test_drive.py": "import robot.drive\nimport pytest\n",
        }
    )
    assert _deps(report, "src/robot/drive.py") == {
        "robot.sensors.laser": (Resolution.INTERNAL, "src/robot/sensors/laser.py"),
    }
    assert _deps(report, "tests/test_drive.py") == {
        "robot.drive": (Resolution.INTERNAL, "src/robot/drive.py"),
        "pytest": (Resolution.EXTERNAL, None),
    }


def test_configured_python_roots_replace_detection() -> None:
    files = {"lib/tools/fmt.py": "", "app.py": "import tools.fmt\n"}
    assert _deps(measure(files), "app.py") == {"tools.fmt": (Resolution.EXTERNAL, None)}
    assert _deps(measure(files, python_roots=("lib",)), "app.py") == {
        "tools.fmt": (Resolution.INTERNAL, "lib/tools/fmt.py"),
    }


def test_namespace_packages_without_init_resolve() -> None:
    report = measure(
        {
            "plugins/camera/driver.py": (
                "from plugins.camera import calib\nfrom . import calib as c\n"
            ),
            "plugins/camera/calib.py": "",
            "main.py": "import plugins.camera.driver\nimport plugins\n",
        }
    )
    assert _deps(report, "plugins/camera/driver.py") == {
        "plugins.camera.calib": (Resolution.INTERNAL, "plugins/camera/calib.py"),
    }
    deps = _deps(report, "main.py")
    assert deps["plugins.camera.driver"] == (Resolution.INTERNAL, "plugins/camera/driver.py")
    assert deps["plugins"] == (Resolution.INTERNAL, None)  # a namespace package: no module


def test_a_script_imports_its_neighbours() -> None:
    report = measure({"tools/run.py": "import helper\n", "tools/helper.py": ""})
    assert _deps(report, "tools/run.py") == {"helper": (Resolution.INTERNAL, "tools/helper.py")}


def test_unresolvable_internal_looking_imports_are_reported() -> None:
    report = measure(
        {
            "pkg/__init__.py": "",
            "pkg/a.py": (
                "from . import missing\nfrom .gone import x\nimport pkg.nothing\nimport os\n"
            ),
            "top.py": "from ... import far\n",
        }
    )
    assert _deps(report, "pkg/a.py") == {
        ".": (Resolution.INTERNAL, "pkg/__init__.py"),  # missing may be a name in __init__
        ".gone": (Resolution.UNRESOLVED, None),
        "pkg.nothing": (Resolution.UNRESOLVED, None),
        "os": (Resolution.EXTERNAL, None),
    }
    assert _deps(report, "top.py") == {"...": (Resolution.UNRESOLVED, None)}


def test_a_name_missing_from_a_namespace_package_is_unresolved() -> None:
    report = measure({"ns/a.py": "from ns import ghost\n", "ns/b.py": ""})
    assert _deps(report, "ns/a.py") == {"ns.ghost": (Resolution.UNRESOLVED, None)}


def test_future_is_ignored_by_default_and_external_modules_count_by_name() -> None:
    source = "from __future__ import annotations\nimport os\nimport os.path\nfrom os import sep\n"
    report = measure({"m.py": source})
    assert _deps(report, "m.py") == {
        "os": (Resolution.EXTERNAL, None),
        "os.path": (Resolution.EXTERNAL, None),
    }
    assert report.element("m.py").s_e == 2
    assert measure({"m.py": source}, ignore_imports=()).element("m.py").s_e == 3
