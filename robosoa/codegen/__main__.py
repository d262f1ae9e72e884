"""``python -m robosoa.codegen gen|validate ...``: the generator without the robosoa CLI."""

from __future__ import annotations

import sys

from robosoa.codegen.cli import main

sys.exit(main(sys.argv[1:]))
