"""Chapter 6 arithmetic: coupling change, change counts Γ, scale factors, ΔVg and cost E.

A page of arithmetic that reads like the thesis (Hestand 2011, pp. 101-107), equation numbers
in comments. The open cases the thesis leaves (a scale with nothing before, negative ΔVg, ...)
follow the conventions in docs/metrics.md and are always flagged in ``notes`` as
``"<code>: <human text>"`` so a convention is never mistaken for a measurement.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from archmetrics.changeset.model import Metrics, Summary


@dataclass(frozen=True, slots=True)
class Sums:
    """Σ over the change sets l_i of one location (eqs. 6.2, 6.5, 6.7, 6.9, 6.16-6.18, 6.31)."""

    pre: Metrics
    post: Metrics
    added: int
    removed: int
    modified: int


@dataclass(frozen=True, slots=True)
class _Scaled:
    """The scale-dependent part of S, shared by a location and the total."""

    loc_scale: float | None
    scaled_changes: float
    vg_scale: float | None
    delta_vg: int
    scaled_delta_vg: float
    cost: float
    notes: tuple[str, ...]


def _loc_scale(loc_pre: int, loc_post: int, changes: int) -> tuple[float | None, list[str]]:
    """λ̂ = λ_post / λ_pre (6.19, 6.20); None (undefined) when λ_pre = 0."""
    if loc_pre == 0:
        return None, [
            "loc_scale_undefined_pre_zero: λ_pre = 0 so λ̂ is undefined (null);"
            " Γ' is taken as Γ (λ̂ = 1)"
        ]
    if loc_post == 0 and changes:
        return 0.0, ["loc_scale_zero_post_empty: λ_post = 0 so λ̂ = 0 and Γ' = 0 although Γ > 0"]
    return loc_post / loc_pre, []


def _vg_scale(vg_pre: int, vg_post: int) -> tuple[float | None, list[str]]:
    """v̂g = Vg_post / Vg_pre (6.32, 6.33); None (undefined) when Vg_pre = 0."""
    if vg_pre == 0:
        return None, [
            "vg_scale_undefined_pre_zero: Vg_pre = 0 so v̂g is undefined (null);"
            " ΔVg' is taken as ΔVg (v̂g = 1)"
        ]
    if vg_post == 0:
        return 0.0, [
            "vg_scale_zero_post_empty: Vg_post = 0 so v̂g = 0 and ΔVg' = 0 although ΔVg < 0"
        ]
    return vg_post / vg_pre, []


def _cost(scaled_changes: float, scaled_delta_vg: float) -> tuple[float, list[str]]:
    """E = Γ'_tot / ΔVg' (6.36, 6.37), and E = 0 when ΔVg' = 0 (6.38, 6.39)."""
    if scaled_delta_vg == 0:
        if scaled_changes:
            return 0.0, [
                "cost_zero_no_complexity_change: ΔVg' = 0 so E = 0 by eq. 6.38 although Γ' > 0"
            ]
        return 0.0, []
    cost = scaled_changes / scaled_delta_vg
    if cost < 0:
        return cost, [
            "cost_negative_complexity_decreased: ΔVg' < 0 so E < 0"
            " (effort per unit of complexity removed)"
        ]
    return cost, []


def _scaled(changes: int, loc_pre: int, loc_post: int, vg_pre: int, vg_post: int) -> _Scaled:
    """λ̂, Γ', v̂g, ΔVg, ΔVg' and E, with a note for every convention applied."""
    if loc_pre == loc_post == vg_pre == vg_post == 0:
        empty = "location_empty: nothing measured before or after; scales undefined (null), E = 0"
        return _Scaled(None, 0.0, None, 0, 0.0, 0.0, (empty,))
    loc_scale, notes = _loc_scale(loc_pre, loc_post, changes)
    scaled_changes = (1.0 if loc_scale is None else loc_scale) * changes  # Γ' = λ̂·Γ  (6.21, 6.25)
    delta_vg = vg_post - vg_pre  # ΔVg = Vg_post − Vg_pre                            (6.29, 6.30)
    vg_scale, vg_notes = _vg_scale(vg_pre, vg_post)
    scaled_delta_vg = (1.0 if vg_scale is None else vg_scale) * delta_vg  # ΔVg' = v̂g·ΔVg (6.34)
    scaled_delta_vg += 0.0  # 0·(−n) is −0.0 in IEEE arithmetic; report it as 0.0
    cost, cost_notes = _cost(scaled_changes, scaled_delta_vg)
    return _Scaled(
        loc_scale,
        scaled_changes,
        vg_scale,
        delta_vg,
        scaled_delta_vg,
        cost,
        (*notes, *vg_notes, *cost_notes),
    )


def _summary(
    deltas: tuple[int, int, int, int],
    counts: tuple[int, int, int],
    sizes: tuple[int, int, int, int],
    notes: Iterable[str],
) -> Summary:
    """S from its coupling deltas, Γ counts and (λ_pre, λ_post, Vg_pre, Vg_post)."""
    added, removed, modified = counts
    loc_pre, loc_post, vg_pre, vg_post = sizes
    changes = added + removed + modified  # Γ = Γ_A + Γ_R + Γ_M                      (6.11, 6.15)
    scaled = _scaled(changes, loc_pre, loc_post, vg_pre, vg_post)
    return Summary(
        *deltas,
        loc_pre=loc_pre,
        loc_post=loc_post,
        loc_scale=scaled.loc_scale,
        added=added,
        removed=removed,
        modified=modified,
        changes=changes,
        scaled_changes=scaled.scaled_changes,
        vg_pre=vg_pre,
        vg_post=vg_post,
        vg_scale=scaled.vg_scale,
        delta_vg=scaled.delta_vg,
        scaled_delta_vg=scaled.scaled_delta_vg,
        cost=scaled.cost,
        notes=(*notes, *scaled.notes),
    )


def location_summary(sums: Sums, notes: Iterable[str] = ()) -> Summary:
    """S(L) for one location from the sums over its change sets; ``notes`` are carried along."""
    pre, post = sums.pre, sums.post
    deltas = (
        post.s_a - pre.s_a,  # Δs_a(L) = s_a(L)_post − s_a(L)_pre                           (6.1)
        post.s_e - pre.s_e,  # Δs_e(L) = s_e(L)_post − s_e(L)_pre                           (6.4)
        post.d_a - pre.d_a,  # Δd_a(L) = d_a(L)_post − d_a(L)_pre                 (p. 102, 6.7)
        post.d_e - pre.d_e,  # Δd_e(L) = d_e(L)_post − d_e(L)_pre                 (p. 102, 6.9)
    )
    # Γ_A(L), Γ_R(L), Γ_M(L) = Σ_i Γ(l_i): already summed over the change sets  (6.16-6.18)
    counts = (sums.added, sums.removed, sums.modified)
    # λ(L) and Vg(L) pre/post = Σ_i over the change sets                         (6.20, 6.31)
    return _summary(deltas, counts, (pre.loc, post.loc, pre.vg, post.vg), notes)


def total_summary(locations: Iterable[Summary], notes: Iterable[str] = ()) -> Summary:
    """S_tot: sums over B, N, F; its scales come from the total λ and Vg (6.19, 6.32).

    So Γ'_tot is λ̂·Γ_tot, not the sum of the locations' Γ'(L), and likewise ΔVg' and E.
    """
    parts = tuple(locations)

    def total(field: str) -> int:
        return sum(int(getattr(s, field)) for s in parts)

    deltas = (
        total("delta_s_a"),  # Δs_a,tot = Δs_a(B) + Δs_a(N) + Δs_a(F)                       (6.3)
        total("delta_s_e"),  # Δs_e,tot = Δs_e(B) + Δs_e(N) + Δs_e(F)                       (6.6)
        total("delta_d_a"),  # Δd_a,tot = Δd_a(B) + Δd_a(N) + Δd_a(F)                       (6.8)
        total("delta_d_e"),  # Δd_e,tot = Δd_e(B) + Δd_e(N) + Δd_e(F)                      (6.10)
    )
    # Γ_A = Γ_A(B) + Γ_A(N) + Γ_A(F), likewise Γ_R and Γ_M                       (6.12-6.14)
    counts = (total("added"), total("removed"), total("modified"))
    sizes = (total("loc_pre"), total("loc_post"), total("vg_pre"), total("vg_post"))
    return _summary(deltas, counts, sizes, notes)
