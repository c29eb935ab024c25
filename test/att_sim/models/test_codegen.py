"""CasADi functions compiled into the cache: the same numbers as CasADi's own evaluation, a library
reused by name, and the uncompiled function when there is no compiler."""
import casadi as ca
import numpy as np

from att_sim.models import codegen


def _function(name):
    x = ca.SX.sym("x", 3)
    return ca.Function(name, [x], [ca.sin(x) * ca.dot(x, x)])


def test_compiled_function_matches_and_is_cached(tmp_path, monkeypatch):
    monkeypatch.setenv("ATT_CACHE_DIR", str(tmp_path))
    f = _function("cg_probe")
    g = codegen.compiled(f)
    libraries = list(tmp_path.glob("cg_probe_*.so"))
    assert len(libraries) == 1 and g.class_name() == "External"
    x = np.array([0.3, -1.2, 2.0])
    np.testing.assert_allclose(np.asarray(g(x)), np.asarray(f(x)), rtol=1e-15, atol=0)
    stamp = libraries[0].stat().st_mtime_ns
    codegen.compiled(f)                      # found by its code's hash, not compiled again
    assert libraries[0].stat().st_mtime_ns == stamp and len(list(tmp_path.glob("*.so"))) == 1


def test_without_a_compiler_the_function_is_returned(tmp_path, monkeypatch):
    monkeypatch.setenv("ATT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(codegen, "_compiler", lambda: None)
    f = _function("cg_plain")
    assert codegen.compiled(f) is f and not list(tmp_path.iterdir())
