"""The start and the check before each stay, written once (filippov.loop.stay): the
decisions the reference driver runs as Python and the kernel compiles."""
import numpy as np
import pytest
from numba import njit

from filippov import rules
from filippov.loop import stay
from filippov.loop.status import GO_ON, NO_RETURN, NO_SLIDING, SECTION_SLIDING
from filippov.system import MINUS, PLUS, SLIDING

BEFORE = [stay.before_stay, njit(stay.before_stay)]


@pytest.mark.parametrize("before", BEFORE, ids=["python", "compiled"])
def test_a_stay_begins_before_the_end_time_and_slides_only_if_built(before):
    assert before(PLUS, 0.5, 1.0, False) == GO_ON
    assert before(SLIDING, 0.5, 1.0, True) == GO_ON
    assert before(SLIDING, 0.5, 1.0, False) == NO_SLIDING
    assert before(MINUS, 1.0, 1.0, True) == NO_RETURN
    assert before(SLIDING, 2.0, 1.0, False) == NO_RETURN  # the end time first


def _start(slides):
    return stay.make_start(lambda ctx: (ctx[0], ctx[1]), lambda ctx: slides)


@pytest.mark.parametrize("h, a, b, sliding, slides, expected", [
    (1.0, -1.0, 1.0, True, True, (GO_ON, PLUS, False)),        # off H: its side
    (-1.0, -1.0, 1.0, True, True, (GO_ON, MINUS, False)),
    (0.0, 1.0, -1.0, True, False, (GO_ON, SLIDING, False)),    # on attracting H
    (0.0, 1.0, -1.0, True, True, (SECTION_SLIDING, SLIDING, False)),  # ... in a section
    (0.0, 1.0, -1.0, False, True, (GO_ON, PLUS, False)),  # not built: no slide, no refusal
])
def test_the_start_mode_and_its_refusal_to_slide_in_a_section(h, a, b, sliding, slides,
                                                             expected):
    status, mode, repelling = _start(slides)(h, 1e-15, sliding, (a, b))
    assert (status, mode, repelling) == expected
    assert (mode, repelling) == ((rules.start_side(h, 1e-15), False) if h != 0.0
                                 else rules.start_on_switch(h, a, b, sliding))


def _plane(section):
    """F_- = (1, 1), F_+ = (1, -1) about H = y: sliding along y = 0 with field (1, 0);
    section_along as the engines' operation (the field of a mode at z + d f)."""
    z, fm, fp = np.array([0.3, 0.0]), np.array([1.0, 1.0]), np.array([1.0, -1.0])
    fields = {MINUS: fm, PLUS: fp, SLIDING: np.array([1.0, 0.0])}
    return (lambda ctx: (z, fm, fp),
            lambda k, mode, d, ctx: section(z + d * fields[mode]))


@pytest.mark.parametrize("section, inside", [
    (lambda z: z[1], True),           # the section is H: the slide stays in it
    (lambda z: z[0] - 0.3, False),    # across the slide
])
def test_a_slide_inside_a_section_is_told_from_one_across_it(section, inside):
    assert bool(stay.make_slides_in(*_plane(section))(0, None)) is inside
