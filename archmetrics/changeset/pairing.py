"""Pairing a replace run's removed and added statements (docs/metrics.md, "Pairing rule").

Rule 2-3: r and a *may pair* when they have the same kind or their token similarity is at
least :data:`SIMILARITY_THRESHOLD`; among order-preserving pairings take the one with the most
pairs, ties broken by the largest summed similarity.

Cost. Similarity is the Indel (LCS) ratio 2·LCS/(|r|+|a|) over the statements' tokens,
computed by rapidfuzz in C (a bit-parallel LCS: a statement of up to 64 tokens costs a few
machine words per pair). The choice is a dynamic programme over the run's m·n cells whose rows
are running maxima. With numpy installed (it comes with the ``api`` extra) the ratios of the
whole run are one rapidfuzz call and each row one numpy operation, so the Python-level work is
O(m + n); without it (a plain ``pip install``, what a CI job installs) the same programme runs
row by row on Python's built-ins (``map``, ``itertools.accumulate``), with the same result and
twenty times the CPU time or more (a 1,000 x 1,000 run of random statements: 1.5-2.2 s
against 0.07-0.1 s; 300 x 300: 0.2 s against 0.01-0.03 s, on a loaded two-core host).
:func:`pair_exact_python` is the rule; tests/changeset checks the numpy path against it.
Runs of more than :data:`EXACT_PAIRING_CELLS` cells, where the table itself would cost tens of
megabytes, are paired greedily and marked approximate; the worst case of a
run is therefore O(m·n) cells up to that bound and O((m + n)·w) beyond.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from itertools import accumulate
from typing import TYPE_CHECKING, Any

from archmetrics.facts import Statement

if TYPE_CHECKING:
    import numpy as np

# numpy and rapidfuzz (60 ms to import) are imported where a run is paired: a scan, a
# report or `--help` never pairs one (docs/performance.md, "Start-up"); numpy is optional

SIMILARITY_THRESHOLD = 0.5
"""Token ratio 2·LCS/T at or above which two statements of different kinds still pair."""

EXACT_PAIRING_CELLS = 1_000_000
"""Largest removed x added product of one replace run paired exactly (about 24 MB of tables)."""

GREEDY_WINDOW = 20
"""How far ahead the greedy fallback looks for a partner of each removed statement."""

SCORE_QUANTUM = 1_000_000
"""Summed similarities are compared in units of 1/SCORE_QUANTUM (exact integer arithmetic)."""

_TOKEN = re.compile(r"\w+|\S")

Pairs = list[tuple[int, int, float]]  # (removed index, added index, their token ratio)


def tokens(text: str) -> tuple[str, ...]:
    """Word tokens and single punctuation characters: what similarity is measured on."""
    return tuple(_TOKEN.findall(text))


def similarity(a: str, b: str) -> float:
    """2·LCS/T over the token sequences of two statement texts (1.0 if both are empty)."""
    from rapidfuzz.distance import Indel

    return float(Indel.normalized_similarity(tokens(a), tokens(b)))


def may_pair(removed: Statement, added: Statement, ratio: float) -> bool:
    return removed.kind == added.kind or ratio >= SIMILARITY_THRESHOLD


def forced(removed: Sequence[Statement], added: Sequence[Statement]) -> Pairs | None:
    """The pairing when there is nothing to choose: as many removed as added statements, each
    of the same kind as its counterpart. Pairing position by position then pairs them all,
    and no other order-preserving pairing does, so rule 3 picks it whatever the token ratios
    are; they are not computed."""
    if len(removed) != len(added):
        return None
    if any(r.kind != a.kind for r, a in zip(removed, added, strict=True)):
        return None
    return [(i, i, 1.0) for i in range(len(removed))]  # 1.0: unused, see StatementChange


def _ratios(removed: Sequence[Statement], added: Sequence[Statement]) -> np.ndarray:
    import numpy as np
    from rapidfuzz import process
    from rapidfuzz.distance import Indel

    return process.cdist(
        [tokens(r.text) for r in removed],
        [tokens(a.text) for a in added],
        scorer=Indel.normalized_similarity,
        dtype=np.float64,
        workers=1,
    )


def pair_exact(removed: Sequence[Statement], added: Sequence[Statement]) -> Pairs:
    """Order-preserving pairing with the most pairs, then the most summed similarity: in
    numpy when it is installed, else :func:`pair_exact_python` (the same pairs)."""
    try:
        import numpy  # noqa: F401
    except ModuleNotFoundError:
        return pair_exact_python(removed, added)
    return pair_exact_numpy(removed, added)


def pair_exact_python(removed: Sequence[Statement], added: Sequence[Statement]) -> Pairs:
    """The rule of :func:`pair_exact_numpy`, on Python's built-ins: each row of ``best``
    is the row above, or the row above shifted by one plus the row's gains, whichever is
    larger, then a running maximum."""
    from rapidfuzz import process
    from rapidfuzz.distance import Indel

    m, n = len(removed), len(added)
    choices = [tokens(a.text) for a in added]
    kinds = [a.kind for a in added]
    scale = (min(m, n) + 1) * SCORE_QUANTUM
    ratios: list[list[float]] = []
    best = [[0] * (n + 1)]
    for r in removed:
        ratio = [0.0] * n
        scores = process.extract(
            tokens(r.text), choices, scorer=Indel.normalized_similarity, limit=None
        )
        for _, score, j in scores:
            ratio[j] = float(score)
        gain = [
            scale + round(x * SCORE_QUANTUM) if k == r.kind or x >= SIMILARITY_THRESHOLD else -1
            for k, x in zip(kinds, ratio, strict=True)
        ]
        above = best[-1]
        paired = map(max, above[1:], map(int.__add__, above, gain))  # skip r_i, or pair a_j
        best.append([0, *accumulate(paired, max)])  # or skip a_j: a running maximum
        ratios.append(ratio)
    return _walk_back(best, ratios, m, n)


def _walk_back(best: Any, ratio: Any, m: int, n: int) -> Pairs:
    """The pairs the table ``best`` chose, read back from its last cell (``best`` and
    ``ratio``: lists of rows, or numpy arrays: O(m + n) cells are read)."""
    pairs: Pairs = []
    i, j = m, n
    while i > 0 and j > 0:
        if best[i][j] == best[i - 1][j]:
            i -= 1
        elif best[i][j] == best[i][j - 1]:
            j -= 1
        else:
            pairs.append((i - 1, j - 1, float(ratio[i - 1][j - 1])))
            i, j = i - 1, j - 1
    return pairs[::-1]


def pair_exact_numpy(removed: Sequence[Statement], added: Sequence[Statement]) -> Pairs:
    """Order-preserving pairing with the most pairs, then the most summed similarity.

    ``best[i, j]`` is the best pairing of the first i removed and j added statements, as one
    integer: pairs x ``scale`` + summed similarity in quanta (``scale`` exceeds any sum, so
    comparing integers compares (pairs, similarity) in that order)."""
    import numpy as np

    m, n = len(removed), len(added)
    ratio = _ratios(removed, added)
    kinds = {kind: number for number, kind in enumerate({s.kind for s in (*removed, *added)})}
    same = np.array([kinds[r.kind] for r in removed])[:, None] == np.array(
        [kinds[a.kind] for a in added]
    )
    allowed = same | (ratio >= SIMILARITY_THRESHOLD)
    scale = (min(m, n) + 1) * SCORE_QUANTUM
    gain = np.where(allowed, scale + np.rint(ratio * SCORE_QUANTUM).astype(np.int64), -1)
    best = np.zeros((m + 1, n + 1), dtype=np.int64)
    for i in range(1, m + 1):
        above = best[i - 1]
        row = np.maximum(above[1:], above[:-1] + gain[i - 1])  # skip r_i, or pair it with a_j
        np.maximum.accumulate(row, out=best[i, 1:])  # or skip a_j: a running maximum
    return _walk_back(best, ratio, m, n)


def pair_greedy(removed: Sequence[Statement], added: Sequence[Statement]) -> Pairs:
    """Fallback for huge runs: each removed statement takes the first partner ahead of the last."""
    from rapidfuzz.distance import Indel

    pairs: Pairs = []
    start = 0
    added_tokens = [tokens(a.text) for a in added]
    for i, r in enumerate(removed):
        mine = tokens(r.text)
        for j in range(start, min(start + GREEDY_WINDOW, len(added))):
            ratio = float(Indel.normalized_similarity(mine, added_tokens[j]))
            if may_pair(r, added[j], ratio):
                pairs.append((i, j, ratio))
                start = j + 1
                break
    return pairs


def pair(removed: Sequence[Statement], added: Sequence[Statement]) -> tuple[Pairs, bool]:
    """The pairs of a replace run, and whether they are exact (False: greedy, approximate)."""
    pairs = forced(removed, added)
    if pairs is not None:
        return pairs, True
    if len(removed) * len(added) <= EXACT_PAIRING_CELLS:
        return pair_exact(removed, added), True
    return pair_greedy(removed, added), False
