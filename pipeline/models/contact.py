"""rockfrag.models.contact - the registry of the bed contact laws, shipped and from plugins.

Input : a law's option name (``SolverOptions.bed``) on the Python side; in the kernels, the law code
        in the parameter record (``params["bed"]``) and the state x = [theta, theta_dot, y, y_dot].
Output: ``CONTACT_LAWS`` (name -> module: the registry), ``LAWS`` (law code -> module) and ``BED_LAWS``
        (option name -> law code), both read from it, and the compiled dispatchers that the bed model and its
        time loop call: ``bed_force_at``, ``contact_indicator``, ``contact_indicators`` and ``bed_full_contact``.

A contact law says how the ground pushes on the base of the block. Each law is one module with its
option name ``NAME`` and the same four compiled hooks (all per unit mass; bed_continuous.py is the
worked example):

    force(x, params, sin_t, cos_t) -> (F, M)   vertical force [m/s^2], its moment about the base centre
                                                [m^2/s^2]; the hot call (every right-hand side)
    indicator(index, x, params) -> value       contact indicator ``index``: its sign changes where the
                                                contact changes (located as an event)
    indicators(x, params, out)                  all N_CONTACT_INDICATORS at once (at every step's end)
    full_contact(x, params, sin_t)              (K_r/m, V/m): small-tilt rocking stiffness about the
        -> (stiffness, energy)                  base centre and elastic energy, whole base in the ground

Indicators 0 and 1 are the penetrations of the -b and +b corners [m] (the time loop reads them for
uplift, impacts and flights); 2 and 3 are the law's own, e.g. where a corner's force switches on or off.

Two ways in, one dispatch:

- **Shipped laws** have a fixed code (0, 1, 2) and a branch in each dispatcher below, which calls the law's hooks
  directly (numba compiles them into the caller, and caches the result on disk).
- **A plugin's law** (a module named by an entry point of the group ``rockfrag.contact_laws``, docs/plugins.md)
  gets a code from ``FIRST_PLUGIN`` on, in the registry's order, and one more branch: the dispatcher calls the
  hook through its address, read at run time from ``params["bed_hooks"]`` (``call_hook``). Each hook is wrapped
  in a C callback (``numba.cfunc``) compiled in each process that runs the law, never cached on disk; the
  dispatchers and every kernel above them stay the same code whatever laws are installed, so their disk cache
  stays valid. Why not pass the hooks as functions: numba cannot cache a kernel that receives functions as
  arguments, and its cache does not invalidate a cached caller when a callee changes, so a dispatcher generated
  for the installed laws would need the whole solver recompiled (no cache) or a cache keyed to the law set.
  ``attach_hooks`` writes the address into the parameter records just before the kernels run
  (``kernels.run_cases``), so a record built in another process (a dask worker's) never carries a stale one.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np

from rockfrag.models import bed_continuous, bed_hunt_crossley, bed_two_spring
from rockfrag.models.fields import PARAMS_DTYPE
from rockfrag.models.jit import COMPILED, kernel
from rockfrag.plugins import GROUPS, Registry

# contact indicators every law reports (see the module docstring)
N_CONTACT_INDICATORS = 4

# ---- the registration: one code per law, and its module (which names it and holds its hooks) ----
CONTINUOUS = 0  # Kelvin-Voigt bed spread over the footprint width
TWO_SPRING = 1  # Kelvin-Voigt springs at the two corners
HUNT_CROSSLEY = 2  # the continuous bed's springs with Hunt-Crossley damping (vanishing with the penetration)
FIRST_PLUGIN = 16  # the code of the first plugin law; the others follow in the registry's order

SHIPPED = {CONTINUOUS: bed_continuous, TWO_SPRING: bed_two_spring, HUNT_CROSSLEY: bed_hunt_crossley}
HOOKS = ("force", "indicator", "indicators", "full_contact")
"""The hooks every law module defines, in the order of a plugin law's table of addresses (``call_hook``)."""

def _law_problem(name: str, law: ModuleType) -> str | None:
    """What is wrong with a plugin's law module (its NAME, its hooks), as one phrase; None if nothing."""
    missing = [hook for hook in HOOKS if not callable(getattr(law, hook, None))]
    if missing:
        return (f"a contact law module needs the hooks {', '.join(HOOKS)}; module {law.__name__} lacks "
                f"{', '.join(missing)}")
    if getattr(law, "NAME", None) != name:
        return f"the module's NAME is {getattr(law, 'NAME', None)!r}; the entry point's name must be the same"
    return None


CONTACT_LAWS = Registry(GROUPS["contact_laws"], ModuleType, check=_law_problem)
"""The contact laws by option name: the shipped ones, then those of the installed plugins (read at import)."""
for _law in SHIPPED.values():
    CONTACT_LAWS[_law.NAME] = _law


def _codes() -> dict[int, ModuleType]:
    """Law code -> module: the shipped codes, then FIRST_PLUGIN, FIRST_PLUGIN + 1, ... for the plugins' laws."""
    shipped = {law: code for code, law in SHIPPED.items()}
    codes, plugin = {}, FIRST_PLUGIN
    for name, law in CONTACT_LAWS.items():
        if law in shipped:
            codes[shipped[law]] = law
        else:
            codes[plugin] = law
            plugin += 1
    return codes


LAWS = _codes()
BED_LAWS = {law.NAME: code for code, law in LAWS.items()}  # option name (SolverOptions.bed) -> law code

UNREGISTERED = "bed contact law code not registered in rockfrag.models.contact"
UNATTACHED = "a plugin contact law's hooks are not attached to the parameters (rockfrag.models.contact.attach_hooks)"


# ---- a plugin law's hooks: C callbacks compiled in this process, called through their addresses --------------

_TABLES: dict[int, tuple[np.ndarray, tuple]] = {}
"""Law code -> (the hooks' addresses, the callbacks that own them): compiled once per process, kept alive."""


def _compile_hooks(law: ModuleType) -> tuple[np.ndarray, tuple]:
    """The law's four hooks as C callbacks of fixed signatures, and the table of their addresses (int64, 4).

    Each callback views its pointers as the arrays and the parameter record the hook takes (no copy) and writes
    what the hook returns into ``out``; see ``call_hook`` for the signatures.
    """
    from numba import carray, cfunc, from_dtype, njit, types
    from numba.core.registry import CPUDispatcher

    force, indicator, indicators, full_contact = (
        hook if isinstance(hook, CPUDispatcher) else njit(hook) for hook in (getattr(law, name) for name in HOOKS))
    double, count = types.CPointer(types.float64), types.int64
    record = types.CPointer(from_dtype(PARAMS_DTYPE))

    @cfunc(types.void(double, count, record, types.float64, types.float64, double))
    def force_hook(x, n, params, sin_t, cos_t, out):
        result = carray(out, 2)
        result[0], result[1] = force(carray(x, n), carray(params, 1)[0], sin_t, cos_t)

    @cfunc(types.void(types.int64, double, count, record, double))
    def indicator_hook(index, x, n, params, out):
        carray(out, 1)[0] = indicator(index, carray(x, n), carray(params, 1)[0])

    @cfunc(types.void(double, count, record, double))
    def indicators_hook(x, n, params, out):
        indicators(carray(x, n), carray(params, 1)[0], carray(out, N_CONTACT_INDICATORS))

    @cfunc(types.void(double, count, record, types.float64, double))
    def full_contact_hook(x, n, params, sin_t, out):
        result = carray(out, 2)
        result[0], result[1] = full_contact(carray(x, n), carray(params, 1)[0], sin_t)

    callbacks = (force_hook, indicator_hook, indicators_hook, full_contact_hook)
    return np.array([callback.address for callback in callbacks], dtype=np.int64), callbacks


def hook_table(code: int) -> float:
    """The address of plugin law ``code``'s table of hooks in this process, as the float ``params`` stores.

    A user-space address is below 2^47 on the 64-bit platforms numba supports, so the float holds it exactly.
    """
    if code not in _TABLES:
        _TABLES[code] = _compile_hooks(LAWS[code])
    address = int(_TABLES[code][0].ctypes.data)
    if address >= 2 ** 53:
        raise RuntimeError(f"the hooks' table of contact law {LAWS[code].NAME!r} lies at {address:#x}, beyond what "
                           "a float64 parameter holds exactly")
    return float(address)


def attach_hooks(params_table: np.ndarray) -> None:
    """Write this process's hook table into every record of ``params_table`` that runs a plugin's law (in place).

    Called by ``kernels.run_cases`` just before the kernels run: the records of the shipped laws get 0.
    """
    codes = params_table["bed"].astype(np.int64)
    params_table["bed_hooks"] = 0.0  # 0: the kernels refuse to call a plugin law's hooks (UNATTACHED)
    if COMPILED:
        for code in np.unique(codes[codes >= FIRST_PLUGIN]):
            if int(code) in LAWS:
                params_table["bed_hooks"][codes == code] = hook_table(int(code))


if COMPILED:
    from llvmlite import ir
    from numba import types
    from numba.extending import intrinsic

    def _hook_codegen(slot, n_out, scalars_before, scalars_after, out_array):
        """The code generator of a call of hook ``slot`` of the table whose address is the intrinsic's first argument.

        The hook gets (``scalars_before`` scalars, x's data, len(x), the parameter record, ``scalars_after``
        scalars, out), out being a stack buffer of ``n_out`` doubles (returned) or the last argument's data.
        """
        def codegen(context, builder, signature, args):
            double, i64 = ir.DoubleType(), ir.IntType(64)
            table = builder.inttoptr(builder.fptosi(args[0], i64), i64.as_pointer())
            rest = list(args[1:])
            before = rest[:scalars_before]
            x_type, x_value = signature.args[1 + scalars_before], rest[scalars_before]
            x = context.make_array(x_type)(context, builder, x_value)
            params = builder.bitcast(rest[scalars_before + 1], ir.IntType(8).as_pointer())
            after = rest[scalars_before + 2:scalars_before + 2 + scalars_after]
            if out_array:
                out_type = signature.args[-1]
                out = context.make_array(out_type)(context, builder, rest[-1]).data
            else:
                buffer = builder.alloca(ir.ArrayType(double, n_out))
                out = builder.bitcast(buffer, double.as_pointer())
            arguments = [*before, x.data, builder.extract_value(x.shape, 0), params, *after, out]
            function_type = ir.FunctionType(ir.VoidType(), [value.type for value in arguments])
            address = builder.load(builder.gep(table, [ir.Constant(i64, slot)]))
            builder.call(builder.inttoptr(address, function_type.as_pointer()), arguments)
            if out_array:
                return context.get_dummy_value()
            values = [builder.load(builder.gep(out, [ir.Constant(ir.IntType(32), i)])) for i in range(n_out)]
            return values[0] if n_out == 1 else context.make_tuple(builder, signature.return_type, values)
        return codegen

    def _contiguous(x):
        """Refuse, at compile time, a state array the hook could not view as contiguous doubles."""
        if not (isinstance(x, types.Array) and x.ndim == 1 and x.layout == "C" and x.dtype == types.float64):
            raise TypeError(f"a contact law hook takes a C-contiguous 1-d float64 state, not {x}")

    @intrinsic
    def _call_force(typingctx, table, x, params, sin_t, cos_t):
        _contiguous(x)
        pair = types.UniTuple(types.float64, 2)
        return pair(table, x, params, sin_t, cos_t), _hook_codegen(0, 2, 0, 2, False)

    @intrinsic
    def _call_indicator(typingctx, table, index, x, params):
        _contiguous(x)
        return types.float64(table, index, x, params), _hook_codegen(1, 1, 1, 0, False)

    @intrinsic
    def _call_indicators(typingctx, table, x, params, out):
        _contiguous(x)
        _contiguous(out)
        return types.void(table, x, params, out), _hook_codegen(2, 0, 0, 0, True)

    @intrinsic
    def _call_full_contact(typingctx, table, x, params, sin_t):
        _contiguous(x)
        pair = types.UniTuple(types.float64, 2)
        return pair(table, x, params, sin_t), _hook_codegen(3, 2, 0, 1, False)

    @kernel
    def plugin_force(x, params, sin_t, cos_t):
        """A plugin law's ``force``, through its address."""
        if params["bed_hooks"] == 0.0:
            raise ValueError(UNATTACHED)
        return _call_force(params["bed_hooks"], x, params, sin_t, cos_t)

    @kernel
    def plugin_indicator(index, x, params):
        """A plugin law's ``indicator``, through its address."""
        if params["bed_hooks"] == 0.0:
            raise ValueError(UNATTACHED)
        return _call_indicator(params["bed_hooks"], np.int64(index), x, params)

    @kernel
    def plugin_indicators(x, params, out):
        """A plugin law's ``indicators``, through its address."""
        if params["bed_hooks"] == 0.0:
            raise ValueError(UNATTACHED)
        _call_indicators(params["bed_hooks"], x, params, out)

    @kernel
    def plugin_full_contact(x, params, sin_t):
        """A plugin law's ``full_contact``, through its address."""
        if params["bed_hooks"] == 0.0:
            raise ValueError(UNATTACHED)
        return _call_full_contact(params["bed_hooks"], x, params, sin_t)
else:  # plain Python: the plugin's hooks themselves
    def plugin_force(x, params, sin_t, cos_t):
        """A plugin law's ``force``."""
        return LAWS[int(params["bed"])].force(x, params, sin_t, cos_t)

    def plugin_indicator(index, x, params):
        """A plugin law's ``indicator``."""
        return LAWS[int(params["bed"])].indicator(index, x, params)

    def plugin_indicators(x, params, out):
        """A plugin law's ``indicators``."""
        LAWS[int(params["bed"])].indicators(x, params, out)

    def plugin_full_contact(x, params, sin_t):
        """A plugin law's ``full_contact``."""
        return LAWS[int(params["bed"])].full_contact(x, params, sin_t)


# ---- the dispatchers: one branch per shipped law, one for the plugins' laws ----------------------------

@kernel
def bed_force_at(x, params, sin_t, cos_t):
    """The law's ``force``: (F [m/s^2], M [m^2/s^2]) of the bed on the block, per unit mass."""
    law = params["bed"]
    if law == CONTINUOUS:
        return bed_continuous.force(x, params, sin_t, cos_t)
    if law == TWO_SPRING:
        return bed_two_spring.force(x, params, sin_t, cos_t)
    if law == HUNT_CROSSLEY:
        return bed_hunt_crossley.force(x, params, sin_t, cos_t)
    if law >= FIRST_PLUGIN:
        return plugin_force(x, params, sin_t, cos_t)
    raise ValueError(UNREGISTERED)


@kernel
def contact_indicator(index, x, params):
    """The law's ``indicator``: contact indicator ``index`` at state x."""
    law = params["bed"]
    if law == CONTINUOUS:
        return bed_continuous.indicator(index, x, params)
    if law == TWO_SPRING:
        return bed_two_spring.indicator(index, x, params)
    if law == HUNT_CROSSLEY:
        return bed_hunt_crossley.indicator(index, x, params)
    if law >= FIRST_PLUGIN:
        return plugin_indicator(index, x, params)
    raise ValueError(UNREGISTERED)


@kernel
def contact_indicators(x, params, out):
    """The law's ``indicators``: all N_CONTACT_INDICATORS values into out."""
    law = params["bed"]
    if law == CONTINUOUS:
        bed_continuous.indicators(x, params, out)
    elif law == TWO_SPRING:
        bed_two_spring.indicators(x, params, out)
    elif law == HUNT_CROSSLEY:
        bed_hunt_crossley.indicators(x, params, out)
    elif law >= FIRST_PLUGIN:
        plugin_indicators(x, params, out)
    else:
        raise ValueError(UNREGISTERED)


@kernel
def bed_full_contact(x, params, sin_t):
    """The law's ``full_contact``: (rocking stiffness K_r/m, elastic energy V/m) [m^2/s^2], whole base down."""
    law = params["bed"]
    if law == CONTINUOUS:
        return bed_continuous.full_contact(x, params, sin_t)
    if law == TWO_SPRING:
        return bed_two_spring.full_contact(x, params, sin_t)
    if law == HUNT_CROSSLEY:
        return bed_hunt_crossley.full_contact(x, params, sin_t)
    if law >= FIRST_PLUGIN:
        return plugin_full_contact(x, params, sin_t)
    raise ValueError(UNREGISTERED)
