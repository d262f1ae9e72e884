"""Code generator (Hestand 2011, p. 93): service descriptor -> typed Python proxy and skeleton.

``generate(descriptor, forms)`` returns the files for the packaging forms (pure);
``write(files, out)`` puts them on disk. Every file starts with the ``@generated`` marker line
so archmetrics leaves generated code out of its measurements.
"""

from __future__ import annotations

from .common import MARKER, GeneratedFile
from .generate import CodegenError, generate, participants, write

__all__ = ["MARKER", "CodegenError", "GeneratedFile", "generate", "participants", "write"]
