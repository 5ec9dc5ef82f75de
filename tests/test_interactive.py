"""The interactive chapter's computation (notebook 91): bad input named early, γ from Corollary 1."""

import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.papers.sun2011.interactive import interactive_design_view


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"delta_bar": -0.1}, "delta_bar"),
    ({"noise": "pink"}, "noise"),
    ({"filter_name": "kalman"}, "filter_name"),
    ({"seed": -1}, "seed"),
    ({"t_from": 5000.0}, "t_from"),
])
def test_bad_input_names_the_parameter(kwargs, name):
    with pytest.raises(InputError, match=name):
        interactive_design_view(**kwargs)
