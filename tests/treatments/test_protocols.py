"""Every built-in treatment meets its family's typed signature
(:mod:`pdverify.corrections.protocols`): a static assembly returns a LinearSystem, a
bond method's closure a Closure, each role its family's type; and the signature check
refuses what does not fit, so it can fail."""
import functools

import pytest

from pdverify.corrections import protocols as P
from pdverify.corrections.builtin import FamilyTreatment
from pdverify.corrections.registry import BondMethod, treatments
from pdverify.pd.closure import Closure
from pdverify.pd.problem import LinearSystem


def _builtins():
    return [t for t in treatments().values() if t.origin == "built-in"]


@pytest.mark.parametrize("name", [t.name for t in _builtins()])
def test_builtin_meets_its_family_protocols(name):
    t = treatments()[name]
    checked = 0
    if "static-state" in t.families:
        build = t.build if isinstance(t, FamilyTreatment) else None
        for fn in (build, t.assemble):
            if fn is not None:
                assert isinstance(fn, P.StaticAssembly)
                assert P.conformance(fn, P.StaticAssembly) is None
                checked += 1
    if isinstance(t, BondMethod):
        assert isinstance(t.closure, P.BondClosure)
        assert P.conformance(t.closure, P.BondClosure) is None
        checked += 1
    for check in (getattr(t, "checker", None), t.check):
        if check is not None:
            assert P.conformance(check, P.ParamCheck) is None
    for family, role in t.roles:
        protocol = P.ROLE_PROTOCOLS[family]
        assert isinstance(role.build, protocol)
        assert P.conformance(role.build, protocol) is None, family
        if role.checker is not None:
            assert P.conformance(role.checker, P.ParamCheck) is None
        checked += 1
    if t.families or t.roles or isinstance(t, BondMethod):
        assert checked, f"{name} serves a family but no signature was checked"


def test_the_builtin_static_assemblies_are_typed():
    """The family treatments' own functions annotate LinearSystem (not Any)."""
    import typing
    for t in _builtins():
        if isinstance(t, FamilyTreatment):
            assert typing.get_type_hints(t.build)["return"] is LinearSystem, t.name


def test_the_signature_check_can_fail():
    def two(problem, params) -> LinearSystem: ...

    def one(params) -> LinearSystem: ...

    def wrong_return(problem, params) -> int: ...

    assert P.conformance(two, P.StaticAssembly) is None
    assert "passes 2" in P.conformance(one, P.StaticAssembly)
    assert "returns" in P.conformance(wrong_return, P.StaticAssembly)
    assert "passes 1" in P.conformance(two, P.BondClosure)
    assert "returns" in P.conformance(functools.partial(two, None), P.BondClosure)

    def closure_of(grid, params) -> Closure: ...

    assert P.conformance(functools.partial(closure_of, None), P.BondClosure) is None
    assert "not callable" in P.conformance(3, P.StaticAssembly)
    # a wave extension is not a clamp: its annotated return says so
    from pdverify.corrections.surface_nodes import wave_extension
    assert "returns" in P.conformance(wave_extension, P.Clamp)
