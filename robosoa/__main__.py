"""``python -m robosoa``: the same as the ``robosoa`` command."""

from __future__ import annotations

import sys

from robosoa.cli import main

sys.exit(main())
