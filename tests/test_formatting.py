"""Display formatting of the screens."""

from app.web.templating import fixed


def test_fixed_drops_the_sign_of_a_value_that_rounds_to_zero():
    assert fixed(-0.0, 4) == "0.0000"
    assert fixed(-1e-12, 5) == "0.00000"
    assert fixed(-0.00006, 4) == "-0.0001"
    assert fixed(12.34567, 3) == "12.346"
