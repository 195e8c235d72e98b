"""A slowing sequence within Richardson's band (:mod:`ngcontact.cell.spectral.estimate_forms`, issue 35).

Two contractions that agree within ``AGREE`` (3) while the last is at least ``DISAGREE`` (2) times slower than the
one before: a mean closure whose differences contracted by 0.057, then 0.16, with an error on the last grid of
about twice its last difference (the next difference grew).  Richardson's first-order tail times ``SPREAD``,
``2 |d_k|``, misses it; the estimate takes the larger of that and the guarded bound on the last two differences,
``max(|d_k|, |d_(k-1)| / 2)`` at first order, and the loose flag names both contractions.
"""
import pytest

from ngcontact.cell.spectral.estimate_forms import (AGREE, DISAGREE, GUARDED, RICHARDSON, guarded_bound, loose_reason,
                                                    slowed, tail_estimate)
from ngcontact.cell.spectral.refinement import ORDER_RATE

#: the differences, oldest first: contractions 0.057, then 0.161
DIFFERENCES = (1.0, 0.057, 0.057 * 0.161)
#: the error of the last level over its last difference (the sequence kept on growing past it)
STALL = 2.075


def _values(differences=DIFFERENCES, start=1.0):
    values = [start]
    for d in differences:
        values.append(values[-1] + d)
    return values


def test_the_contractions_lie_where_agree_and_disagree_overlap():
    before, last = DIFFERENCES[1] / DIFFERENCES[0], DIFFERENCES[2] / DIFFERENCES[1]
    assert last < AGREE * before and slowed(last, before) and last >= DISAGREE * before


def test_a_slowing_sequence_bounds_an_error_of_twice_its_last_difference():
    """Main's Richardson tail, ``2 |d_k|`` (rate held to 1/2), lies below the error ``2.075 |d_k|``; the guarded
    bound since the fast contraction, ``|d_(k-1)| / 2``, bounds it, within ten times, and below the whole
    window's guarded bound (the first difference carried at first order, ``|d_(k-2)| / 4``)."""
    values = _values()
    error = STALL * DIFFERENCES[-1]
    estimate, form, remark = tail_estimate(values, False, ORDER_RATE["mean_closure"])
    assert 1.0 <= estimate / error <= 10.0
    assert form == RICHARDSON and "slower than the one before" in remark
    assert estimate == pytest.approx(DIFFERENCES[1] / 2)
    assert estimate < guarded_bound(list(DIFFERENCES[::-1]))[0] == pytest.approx(DIFFERENCES[0] / 4)
    assert "the last two contractions disagree (0.057, then 0.16)" in loose_reason(values, estimate, form)


def test_a_sequence_slowing_less_keeps_richardsons_tail():
    """Contractions 0.1, then 0.28 (slowing, ``c >= 1/4``): Richardson's ``2 |d_k|`` already exceeds ``|d_(k-1)| /
    2``, and is the estimate, its remark the rate alone; agreeing contractions that do not slow (0.3, then 0.2)
    take Richardson's tail as before."""
    slowing = (1.0, 0.1, 0.028)
    estimate, form, remark = tail_estimate(_values(slowing), False, ORDER_RATE["mean_closure"])
    assert form == RICHARDSON and estimate == pytest.approx(2 * 0.028) and remark == "rate 0.5"
    quickening = (1.0, 0.3, 0.06)
    estimate, form, remark = tail_estimate(_values(quickening), False, ORDER_RATE["mean_closure"])
    assert form == RICHARDSON and estimate == pytest.approx(2 * 0.06) and remark == "rate 0.5"


def test_contractions_beyond_agree_still_take_the_whole_windows_guarded_bound():
    """Contractions 0.05, then 0.2 (four times slower): not Richardson's band; the guarded bound of the window."""
    differences = (1.0, 0.05, 0.01)
    estimate, form, _ = tail_estimate(_values(differences), False, ORDER_RATE["mean_closure"])
    assert form == GUARDED and estimate == pytest.approx(guarded_bound(list(differences[::-1]))[0])
