"""engine.verdict: the band edges, the material rule, the statistics against hand-computed values."""

import math

import pytest

from engine.verdict import series_statistics, verdict, worst

INNER, OUTER = -1, 1


@pytest.mark.parametrize("actual, material, expected", [
    (10.0, INNER, "ok"), (10.1, INNER, "ok"), (9.9, INNER, "ok"),            # on the band and its edges
    (10.1 + 1e-6, INNER, "scrap"), (9.9 - 1e-6, INNER, "rework"),            # bore: over = material missing
    (10.1 + 1e-6, OUTER, "rework"), (9.9 - 1e-6, OUTER, "scrap"),            # spigot: over = material left
    (10.2, None, "scrap"), (9.8, None, "scrap"),                             # a position cannot be reworked
])
def test_band_edges_and_the_material_side(actual, material, expected):
    assert verdict(actual, 9.9, 10.1, material) == expected


def test_a_limit_typed_in_decimal_counts_as_on_the_band():
    assert 0.1 + 0.2 > 0.3                           # binary: the sum is not the typed number
    assert verdict(0.3, 0.0, 0.1 + 0.2, INNER) == "ok"


def test_no_band_or_no_value_is_not_decidable_and_the_scrap_rule():
    assert verdict(10.0, None, 10.1, INNER) == "not_decidable"
    assert verdict(None, 9.9, 10.1, INNER) == "not_decidable"
    assert verdict(math.nan, 9.9, 10.1, INNER) == "not_decidable"
    assert verdict(9.0, 9.9, 10.1, INNER, rule="scrap") == "scrap"
    with pytest.raises(ValueError, match="rule"):
        verdict(9.0, 9.9, 10.1, INNER, rule="lenient")


def test_the_worst_verdict():
    assert worst(["ok", "not_decidable"]) == "not_decidable"
    assert worst(["ok", "rework", "not_decidable"]) == "rework"
    assert worst(["scrap", "rework"]) == "scrap"
    assert worst([]) == "not_decidable"


def test_individuals_statistics_by_hand():
    xs = [10.0, 10.2, 9.9, 10.1, 10.3]
    s = series_statistics(xs, lower=9.4, upper=10.6)
    mean = 50.5 / 5                                              # 10.1
    mr = (0.2 + 0.3 + 0.2 + 0.2) / 4                             # 0.225
    within = mr / 1.128
    sd = math.sqrt((0.01 + 0.01 + 0.04 + 0.0 + 0.04) / 4)      # 0.158113...
    assert s.n == 5 and s.mean == pytest.approx(mean)
    assert s.sigma == pytest.approx(sd) and s.sigma_within == pytest.approx(within)
    assert (s.lcl, s.ucl) == pytest.approx((mean - 3 * within, mean + 3 * within))
    assert s.cp == pytest.approx(1.2 / (6 * within)) and s.cpk == pytest.approx(0.5 / (3 * within))
    assert s.pp == pytest.approx(1.2 / (6 * sd)) and s.ppk == pytest.approx(0.5 / (3 * sd))


def test_too_few_values():
    assert series_statistics([]).mean is None
    one = series_statistics([3.0], 2.0, 4.0)
    assert one.n == 1 and one.mean == 3.0 and one.sigma is None and one.cpk is None
