"""Use cases: each CLI command calls one function here, which wires sources, parsers, metrics."""
