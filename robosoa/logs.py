"""Structured logging: stdlib ``logging`` with a one-JSON-object-per-line formatter."""

from __future__ import annotations

import json
import logging
import sys
from typing import Any, TextIO

_STANDARD = set(vars(logging.makeLogRecord({}))) | {"message", "asctime"}


class JsonFormatter(logging.Formatter):
    """Formats a record as one JSON line: time, level, logger, message and any ``extra`` keys."""

    def format(self, record: logging.LogRecord) -> str:
        """The JSON line for ``record``."""
        data: dict[str, Any] = {
            "time": round(record.created, 6), "level": record.levelname,
            "logger": record.name, "message": record.getMessage(),
        }
        for key, value in vars(record).items():
            if key not in _STANDARD and not key.startswith("_"):
                data[key] = value
        if record.exc_info:
            data["exception"] = self.formatException(record.exc_info)
        return json.dumps(data, default=str)


def configure(level: str = "WARNING", json_lines: bool = True,
              stream: TextIO | None = None) -> logging.Handler:
    """Send ``robosoa.*`` logs to ``stream`` (stderr), as JSON lines unless told otherwise."""
    handler = logging.StreamHandler(stream or sys.stderr)
    handler.setFormatter(JsonFormatter() if json_lines else logging.Formatter(
        "%(asctime)s %(levelname)s %(name)s: %(message)s"))
    logger = logging.getLogger("robosoa")
    logger.handlers[:] = [handler]
    logger.setLevel(level.upper())
    logger.propagate = False
    return handler
