"""``robosoa gen DESCRIPTOR.xml --out DIR [--form ...]`` and ``robosoa validate DESCRIPTOR.xml``.

Exit codes: 0 ok, 2 bad input (one line per problem on stderr, never a traceback).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import TextIO

from robosoa.descriptor import DescriptorError, Packaging, load
from robosoa.descriptor.loader import MAX_DESCRIPTOR_BYTES

from .generate import CodegenError, generate, write


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="robosoa", description="Service descriptor tools.")
    sub = parser.add_subparsers(dest="command", required=True)
    gen = sub.add_parser("gen", help="generate proxy and skeleton packages from a descriptor")
    gen.add_argument("descriptor", help="service descriptor (XML)")
    gen.add_argument("--out", required=True, help="directory to write the packages into")
    gen.add_argument(
        "--form",
        action="append",
        default=[],
        choices=[p.value for p in Packaging],
        help="packaging form to generate (repeatable; default: every declared participant)",
    )
    check = sub.add_parser("validate", help="check a descriptor against schema and semantics")
    check.add_argument("descriptor", help="service descriptor (XML)")
    for command in (gen, check):
        command.add_argument("--max-size", type=int, default=MAX_DESCRIPTOR_BYTES,
                             metavar="BYTES", help="refuse larger descriptor files "
                             f"(default {MAX_DESCRIPTOR_BYTES})")
    return parser


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Execute parsed ``args``; report to ``out``/``err``; return the exit code."""
    try:
        descriptor = load(args.descriptor, max_bytes=args.max_size)
        if args.command == "validate":
            names = ", ".join(op.name for op in descriptor.operations)
            print(
                f"{args.descriptor}: ok: service '{descriptor.name}' {descriptor.version} "
                f"({descriptor.pattern}; operations: {names})",
                file=out,
            )
            return 0
        files = generate(descriptor, [Packaging(f) for f in args.form])
        for path in write(files, args.out):
            print(path, file=out)
        return 0
    except DescriptorError as exc:
        for problem in exc.problems:
            print(problem, file=err)
    except (CodegenError, OSError) as exc:
        print(f"robosoa: {exc}", file=err)
    return 2


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry; ``argv`` excludes the program name.

    ``argv`` starts with ``gen`` or ``validate``; anything else is taken as the arguments of
    ``gen`` (that is how ``robosoa gen ...`` hands over what follows its subcommand).
    """
    words = list(sys.argv[1:] if argv is None else argv)
    if words and words[0] not in ("gen", "validate", "-h", "--help"):
        words.insert(0, "gen")
    try:
        args = _parser().parse_args(words)
    except SystemExit as exc:  # argparse already printed a one-line usage error
        return exc.code if isinstance(exc.code, int) else 2
    return run(args, sys.stdout, sys.stderr)
