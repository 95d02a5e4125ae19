"""The faces' vocabulary (pdverify.pd.faces): a face is looked up by its name and read
as axis, side and outward sign; a problem's conditions come back as faces."""
import pytest

from pdverify.pd.faces import FACES, Face, box_faces, face_names
from pdverify.pd.problem import FaceCondition, StaticProblem


def test_a_face_by_name_reads_axis_side_and_sign():
    for name, axis, side, sign in (("x-", 0, 0, -1.0), ("x+", 0, 1, 1.0),
                                   ("y-", 1, 0, -1.0), ("z+", 2, 1, 1.0)):
        f = Face.named(name)
        assert (f.name, f.axis, f.side, f.sign) == (name, axis, side, sign)
        assert Face.at(axis, side) is f and Face.named(f) is f
    assert [f.name for f in box_faces(3)] == list(FACES)
    assert face_names(2) == ("x-", "x+", "y-", "y+")


@pytest.mark.parametrize("bad", [0, 1, "x", "left"])
def test_a_face_number_or_unknown_name_is_refused(bad):
    with pytest.raises(ValueError, match="allowed x-, x\\+, y-"):
        Face.named(bad)


def test_a_problem_lists_its_faces_in_order_as_faces():
    """conditions keyed by name in any order; faces(), prescribed() and loaded() give
    Face values in the faces' order."""
    def traction(x, n):
        return 0 * x
    conditions = {"y+": FaceCondition(traction=traction), "x-": FaceCondition(prescribed=(0, 1)),
                  "y-": FaceCondition(prescribed=(1,))}
    p = StaticProblem(lengths=(1.0, 1.0), origin=(0.0, 0.0), spacing=0.25, stencil=None,
                      constants=None, influence=None, conditions=conditions,
                      exact=lambda x: 0 * x)
    assert [f.name for f, _ in p.faces()] == ["x-", "y-", "y+"]
    assert [(f.name, k) for f, k, _ in p.prescribed()] == [("x-", 0), ("x-", 1), ("y-", 1)]
    assert [(f.name, f.axis, f.sign) for f, _ in p.loaded()] == [("y+", 1, 1.0)]
