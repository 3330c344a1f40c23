"""The encoder's last crossed edge (``CrossedEdge``) against hand-worked sequences."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arcosim.fmu.flexchain.control.encoder_edge import CrossedEdge

COUNT = 2 * math.pi / 2000  # one count of a 2000-count encoder (rad)
H = 1e-3


def _velocities(readings: list[float], half: float = COUNT / 2) -> list[float]:
    edge = CrossedEdge(readings[0], half)
    return [edge.step(H, r) for r in readings[1:]]


def test_a_dither_across_one_edge_is_no_motion() -> None:
    """Counts 5, 6, 5, 6, 5: the motor crosses the edge at 6 counts back and forth; after
    the first crossing (half a count from the first count's middle) it reads 0."""
    v = _velocities([c * COUNT for c in (5, 6, 5, 6, 5, 5)])
    assert v[0] == pytest.approx(0.5 * COUNT / H, rel=1e-12)
    assert v[1:] == [0.0] * 4


def test_motion_in_one_direction_is_the_backward_difference() -> None:
    """A motor moving on (one or several counts a step) reads what the plain backward
    difference of the counts reads, once it has left its first count."""
    counts = np.array([0, 1, 3, 4, 4, 6, 9, 9, 10])
    v = _velocities(list(counts * COUNT))
    assert v[1:] == pytest.approx(list(np.diff(counts)[1:] * COUNT / H), rel=1e-12)


def test_a_reversal_moves_the_edge_by_the_counts_past_it() -> None:
    """Up to count 8, then down to 6: the edges crossed are 8 (rising into count 8), then
    8 again (falling into count 7, its upper edge) and 7 (falling into count 6)."""
    v = _velocities([c * COUNT for c in (6, 7, 8, 7, 6)])
    assert v[1:] == pytest.approx([COUNT / H, 0.0, -COUNT / H], rel=1e-12)


def test_an_exact_angle_gives_the_backward_difference() -> None:
    """With no counts (half a count of 0) the edge is the angle itself."""
    angles = [0.0, 0.3e-3, 0.1e-3, 0.25e-3]
    v = _velocities(angles, half=0.0)
    assert v == pytest.approx(list(np.diff(angles) / H), rel=1e-12)


def _slides(readings: list[int], within: float) -> list[float]:
    edge = CrossedEdge(readings[0] * COUNT, COUNT / 2)
    out = []
    for r in readings[1:]:
        edge.step(H, r * COUNT)
        out.append(edge.sliding(within))
    return out


def test_a_motor_crossing_edges_one_way_slides_until_the_next_edge_is_due() -> None:
    """Counts rising every 3 steps: sliding up from the second new edge on, and still
    3 steps after the last one; the 4th step without a new edge is past it."""
    counts = [0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 3, 3]
    assert _slides(counts, within=5 * H) == [0.0] * 3 + [1.0] * 7 + [0.0]


def test_a_slide_whose_steps_differ_in_their_last_bits_slides_when_late_allows() -> None:
    """Edges 2, 3, … steps apart, the third interval's steps an ulp longer than the
    second's (a log's time column read back): by the edge's own rule the motor is stuck
    on the step where the time since equals the last interval but for that ulp; allowed
    two steps late, it slides throughout."""
    longer = math.nextafter(H, 1.0)
    counts = [0, 1, 1, 2, 2, 2, 3, 3]
    steps = [H, H, H, longer, longer, H, H]
    edge, strict, late = CrossedEdge(0.0, COUNT / 2), [], []
    for r, h in zip(counts[1:], steps):
        edge.step(h, r * COUNT)
        strict.append(edge.sliding(5 * H))
        late.append(edge.sliding(5 * H, 2 * H))
    assert strict == [0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0]
    assert late == [0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0]


def test_falling_edges_slide_down() -> None:
    assert _slides([5, 4, 3, 2], within=H)[1:] == [-1.0, -1.0]


def test_edges_further_apart_than_within_do_not_slide() -> None:
    """One new edge every 4 steps against a limit of 3 steps: too slow to be taken as
    sliding (a motor that may be sticking between them)."""
    counts = [0, 1, 1, 1, 1, 2, 2, 2, 2, 3]
    assert _slides(counts, within=3 * H) == [0.0] * 9


def test_a_dither_or_a_reversal_does_not_slide() -> None:
    """Across one edge and back (the hold's dither): no new edge, no heading; a reversal
    ends the slide up as soon as the reading falls back, and one down starts at the
    second new edge down."""
    assert _slides([5, 6, 5, 6, 5, 6], within=5 * H) == [0.0] * 5
    assert _slides([5, 6, 7, 6, 5, 4], within=5 * H) == [0.0, 1.0, 0.0, 0.0, -1.0]


def _headings(readings: list[int], expected: float, within: float) -> list[float]:
    edge = CrossedEdge(readings[0] * COUNT, COUNT / 2)
    out = []
    for r in readings[1:]:
        edge.step(H, r * COUNT)
        out.append(edge.heading(expected, within))
    return out


def test_the_expected_heading_holds_until_an_edge_goes_against_it() -> None:
    """Expected +1 (the reference moving up): kept while the counts rise or stay; an edge
    crossed downwards (the motor turned round) leaves it to the samples (0) for
    ``within``, then +1 again."""
    assert _headings([5, 5, 6, 6], 1.0, within=2 * H) == [1.0] * 3
    assert _headings([5, 4, 4, 4, 4], 1.0, within=2 * H) == [0.0, 0.0, 0.0, 1.0]


def test_edges_sliding_against_the_expected_heading_win() -> None:
    """Counts falling a count a step against an expected +1: after the second new edge the
    edges' −1; with nothing expected, the edges alone (``sliding``)."""
    assert _headings([5, 4, 3, 2], 1.0, within=2 * H) == [0.0, -1.0, -1.0]
    assert _headings([5, 6, 7, 7, 7, 7], 0.0, within=2 * H) == [0.0, 1.0, 1.0, 0.0, 0.0]


def test_back_over_the_same_edge_ends_a_slide() -> None:
    """Rising a count a step, then back into the count below the last edge: the motor
    turned, so no slide, though no new edge was crossed."""
    assert _slides([0, 1, 2, 3, 2, 2], within=5 * H) == [0.0, 1.0, 1.0, 0.0, 0.0]


def test_edges_exactly_within_apart_slide() -> None:
    """Edges 10 steps of 1 ms apart against a limit of 10 ms: a slide, though ten steps of
    1e-3 add up to a float just over 0.01."""
    counts = [0, 1] + [1] * 9 + [2]
    assert _slides(counts, within=10 * H)[-1] == 1.0
