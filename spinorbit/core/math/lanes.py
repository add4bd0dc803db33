"""Doubles in one SIMD register: numba types for running scalar kernels on eight states at once, and for
the 3-vector and quaternion arithmetic of one state four components at a time.

``Lanes`` is an LLVM ``<8 x double>`` and ``LaneMask`` an ``<8 x i1>``. Arithmetic (+, −, ×, /, unary
−, ``abs``, ``math.sqrt``, :func:`spinorbit.core.math.ddouble.fma`) and comparisons act lane by lane,
with a double on either side broadcast to every lane. Each lane's operation is the IEEE-754 operation
of the scalar code (no reassociation, no contraction), so a kernel written once and compiled for
floats and for ``Lanes`` gives every lane the scalar result bit for bit. Where the scalar code
branches, the lane form keeps each lane's own path with :func:`select` and loops while
:func:`any_lane` holds (the drivers of :func:`spinorbit.core.math.carlson.rf_lanes` and
:func:`spinorbit.core.free_motion.flow_constants.complete_k_pi_lanes`).

Why: the set-up of one torque-free state is bound by the divider and the square root (the AGM and
Carlson's duplication), which a scalar loop uses one double at a time; ``<8 x double>`` issues eight
(``docs/design.md``, "Eight states in one register").

``QuadLanes`` (``<32 x double>``, component c of member l in element 8c + l): the Quad kernels compiled on
member rows (2-d arrays (n, 8), row i one quantity of eight members) run eight members in lanes, each
member's arithmetic the Quad kernel's, bit for bit (the Quad helpers take both forms).

``Quad`` is an LLVM ``<4 x double>`` with +, −, ×, /, unary − and :func:`~spinorbit.core.math.ddouble.fma`
(not ``abs``, ``math.sqrt`` or comparisons, which no Quad kernel needs), plus what component-wise
vector code needs: :func:`quad` (four doubles packed), :func:`quad_lane` (one
out), :func:`quad_shuffle` (a permutation fixed at compile time, with zeros), :func:`load_quad`,
:func:`store_quad` and :func:`load_broadcast_quad` (one double of an array in every lane). A quaternion
fills one, a 3-vector three of its lanes; the Taylor recurrences
(:mod:`spinorbit.core.integrators.taylor_recurrences`) run their Cauchy products on them.
"""

import math
import operator

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, models, overload, register_model

WIDTH = 8
QUAD_WIDTH = 4


class LanesType(types.Type):
    """numba type of ``width`` doubles in one vector register (``Lanes``: 8, ``Quad``: 4)."""

    def __init__(self, width, name):
        self.width = width
        super().__init__(name=name)


class LaneMaskType(types.Type):
    """numba type of eight booleans, one per lane."""

    def __init__(self):
        super().__init__(name="LaneMask")


lanes_type = LanesType(WIDTH, "Lanes")
quad_type = LanesType(QUAD_WIDTH, "Quad")
#: Four components of eight members: component c of member l in element c·8 + l (``QuadLanes``).
quad_lanes_type = LanesType(QUAD_WIDTH * WIDTH, "QuadLanes")
mask_type = LaneMaskType()
_VECTOR = ir.VectorType(ir.DoubleType(), WIDTH)
_QUAD = ir.VectorType(ir.DoubleType(), QUAD_WIDTH)
_MASK = ir.VectorType(ir.IntType(1), WIDTH)
_QUAD_LANES = ir.VectorType(ir.DoubleType(), QUAD_WIDTH * WIDTH)


@register_model(LanesType)
class _LanesModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, ir.VectorType(ir.DoubleType(), fe_type.width))


@register_model(LaneMaskType)
class _MaskModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _MASK)


def _vector_type_of(*operand_types):
    """The one vector type among the operands (None if there is none, or two of different widths), where
    QuadLanes absorbs Lanes and Quad (spread over its components or its members, :func:`_as_vector`)."""
    vectors = {t for t in operand_types if isinstance(t, LanesType)}
    if quad_lanes_type in vectors:
        vectors -= {lanes_type, quad_type}
    return vectors.pop() if len(vectors) == 1 else None


def _as_vector(context, builder, value, value_type, width=WIDTH):
    """The LLVM vector of a Lanes or Quad value, or of a number broadcast to ``width`` lanes; into a
    QuadLanes (width 32) a Lanes value goes to every component (one value per member) and a Quad value
    to every member (one value per component)."""
    if isinstance(value_type, LanesType):
        if value_type.width == width:
            return value
        if value_type == lanes_type:
            mask = [lane for _ in range(QUAD_WIDTH) for lane in range(WIDTH)]
        else:
            mask = [component for component in range(QUAD_WIDTH) for _ in range(WIDTH)]
        return builder.shuffle_vector(value, value, ir.Constant(ir.VectorType(ir.IntType(32), width), mask))
    scalar = context.cast(builder, value, value_type, types.float64)
    return _splat(builder, scalar, width)


def _splat(builder, scalar, width=WIDTH):
    vector = ir.Constant(ir.VectorType(ir.DoubleType(), width), ir.Undefined)
    vector = builder.insert_element(vector, scalar, ir.Constant(ir.IntType(32), 0))
    return builder.shuffle_vector(vector, vector, ir.Constant(ir.VectorType(ir.IntType(32), width), [0] * width))


def _is_operand(t):
    return isinstance(t, (LanesType, types.Float, types.Integer))


def _is_lanes_operand(t):
    """Lanes or a number: an operand of the eight-lane selections."""
    return t == lanes_type or isinstance(t, (types.Float, types.Integer))


def _are_operands(*operand_types):
    """All numbers or vectors, with exactly one vector type among them."""
    return all(_is_operand(t) for t in operand_types) and _vector_type_of(*operand_types) is not None


def _lanes_binary(emit, comparison):
    """An intrinsic applying ``emit(builder, x, y)`` to two operands lane by lane (numbers broadcast),
    returning their vector type (arithmetic) or LaneMask (``comparison``, eight lanes only)."""

    @intrinsic
    def kernel(typingctx, a, b):
        vector_type = _vector_type_of(a, b)
        if not _are_operands(a, b) or (comparison and vector_type != lanes_type):
            return None

        def codegen(context, builder, signature, args):
            x = _as_vector(context, builder, args[0], signature.args[0], vector_type.width)
            y = _as_vector(context, builder, args[1], signature.args[1], vector_type.width)
            return emit(builder, x, y)

        return (mask_type if comparison else vector_type)(a, b), codegen

    return kernel


def _register_binary(python_operator, kernel):
    """``python_operator`` on (vector or number, vector or number), one vector type, by ``kernel``."""

    def implementation(a, b):
        if _are_operands(a, b):
            return lambda a, b: kernel(a, b)
        return None

    overload(python_operator)(implementation)


for _instruction, _operators in (("fadd", (operator.add, operator.iadd)), ("fsub", (operator.sub, operator.isub)),
                                 ("fmul", (operator.mul, operator.imul)),
                                 ("fdiv", (operator.truediv, operator.itruediv))):
    _kernel = _lanes_binary(lambda builder, x, y, name=_instruction: getattr(builder, name)(x, y), False)
    for _operator in _operators:
        _register_binary(_operator, _kernel)

# ordered comparisons: false in a lane where either operand is NaN, as the scalar comparison is
for _operator, _predicate in ((operator.lt, "<"), (operator.le, "<="), (operator.gt, ">"),
                              (operator.ge, ">="), (operator.eq, "==")):
    _register_binary(_operator, _lanes_binary(
        lambda builder, x, y, predicate=_predicate: builder.fcmp_ordered(predicate, x, y), True))


@intrinsic
def _mask_and(typingctx, a, b):
    if a != mask_type or b != mask_type:
        return None
    return mask_type(a, b), lambda context, builder, signature, args: builder.and_(*args)


@intrinsic
def _mask_or(typingctx, a, b):
    if a != mask_type or b != mask_type:
        return None
    return mask_type(a, b), lambda context, builder, signature, args: builder.or_(*args)


@intrinsic
def _mask_not(typingctx, a):
    if a != mask_type:
        return None
    return mask_type(a), lambda context, builder, signature, args: builder.not_(args[0])


@overload(operator.and_)
def _overload_and(a, b):
    if a == mask_type and b == mask_type:
        return lambda a, b: _mask_and(a, b)
    return None


@overload(operator.or_)
def _overload_or(a, b):
    if a == mask_type and b == mask_type:
        return lambda a, b: _mask_or(a, b)
    return None


@overload(operator.invert)
def _overload_invert(a):
    if a == mask_type:
        return lambda a: _mask_not(a)
    return None


def _vector_intrinsic(builder, name, *values):
    """Call the LLVM intrinsic ``name`` on <W x double> operands (llvmlite names no vector overloads)."""
    vector = values[0].type
    signature = ir.FunctionType(vector, [vector] * len(values))
    function = cgutils.get_or_insert_function(builder.module, signature, f"{name}.v{vector.count}f64")
    return builder.call(function, list(values))


@intrinsic
def _neg(typingctx, a):
    if not isinstance(a, LanesType):
        return None
    return a(a), lambda context, builder, signature, args: builder.fneg(args[0])


@intrinsic
def _abs(typingctx, a):
    if a != lanes_type:
        return None
    return lanes_type(a), lambda context, builder, signature, args: _vector_intrinsic(builder, "llvm.fabs", args[0])


@intrinsic
def _sqrt(typingctx, a):
    if a != lanes_type:
        return None
    return lanes_type(a), lambda context, builder, signature, args: _vector_intrinsic(builder, "llvm.sqrt", args[0])


@overload(operator.neg)
def _overload_neg(a):
    if isinstance(a, LanesType):
        return lambda a: _neg(a)
    return None


@overload(abs)
def _overload_abs(a):
    if a == lanes_type:
        return lambda a: _abs(a)
    return None


@overload(math.sqrt)
def _overload_sqrt(a):
    if a == lanes_type:
        return lambda a: _sqrt(a)
    return None


def fma_typing(a, b, c):
    """(signature, codegen) of a·b + c rounded once in every lane (``llvm.fma``, numbers broadcast)
    when an operand is ``Lanes`` or ``Quad``, else None: :func:`spinorbit.core.math.ddouble.fma` takes
    this branch, so the one fma of the package serves every form."""
    if not _are_operands(a, b, c):
        return None
    vector_type = _vector_type_of(a, b, c)

    def codegen(context, builder, signature, args):
        values = [_as_vector(context, builder, v, t, vector_type.width) for v, t in zip(args, signature.args)]
        return _vector_intrinsic(builder, "llvm.fma", *values)

    return vector_type(a, b, c), codegen


@intrinsic
def select(typingctx, mask, a, b):
    """Lane by lane: a where ``mask`` holds, else b (numbers broadcast); with a QuadLanes operand, member
    by member in all four components."""
    if mask != mask_type:
        return None
    wide = quad_lanes_type in (a, b)
    if not all(_is_lanes_operand(t) or (wide and t == quad_lanes_type) for t in (a, b)):
        return None
    result_type = quad_lanes_type if wide else lanes_type

    def codegen(context, builder, signature, args):
        x = _as_vector(context, builder, args[1], signature.args[1], result_type.width)
        y = _as_vector(context, builder, args[2], signature.args[2], result_type.width)
        condition = args[0]
        if wide:  # the member's mask in each of the four components
            mask_wide = [lane for _ in range(QUAD_WIDTH) for lane in range(WIDTH)]
            condition = builder.shuffle_vector(condition, condition,
                                               ir.Constant(ir.VectorType(ir.IntType(32), len(mask_wide)), mask_wide))
        return builder.select(condition, x, y)

    return result_type(mask, a, b), codegen


@intrinsic
def any_lane(typingctx, mask):
    """True if ``mask`` holds in at least one lane."""
    if mask != mask_type:
        return None

    def codegen(context, builder, signature, args):
        signature = ir.FunctionType(ir.IntType(1), [_MASK])
        function = cgutils.get_or_insert_function(builder.module, signature, f"llvm.vector.reduce.or.v{WIDTH}i1")
        return builder.call(function, [args[0]])

    return types.boolean(mask), codegen


@intrinsic
def broadcast(typingctx, value):
    """A number in every lane."""
    if not isinstance(value, (types.Float, types.Integer)):
        return None
    return lanes_type(value), lambda context, builder, signature, args: _as_vector(context, builder, args[0], signature.args[0])


def _is_vector_array(t):
    """A one-dimensional C-contiguous float64 array: consecutive doubles are one vector."""
    return isinstance(t, types.Array) and t.dtype == types.float64 and t.ndim == 1 and t.layout == "C"


def _vector_load(vector_type, doc):
    """An intrinsic loading ``vector_type.width`` consecutive doubles of a C-contiguous float64 array."""

    def load(typingctx, array, start):
        if not (_is_vector_array(array) and isinstance(start, types.Integer)):
            return None

        def codegen(context, builder, signature, args):
            pointer = _element_pointer(context, builder, signature.args[0], *args)
            vector = ir.VectorType(ir.DoubleType(), vector_type.width)
            return builder.load(builder.bitcast(pointer, vector.as_pointer()), align=8)

        return vector_type(array, start), codegen

    load.__doc__ = doc
    return intrinsic(load)


def _vector_store(vector_type, doc):
    """An intrinsic storing a ``vector_type`` value into consecutive doubles of a C-contiguous float64 array."""

    def store(typingctx, array, start, value):
        if not (_is_vector_array(array) and isinstance(start, types.Integer) and value == vector_type):
            return None

        def codegen(context, builder, signature, args):
            pointer = _element_pointer(context, builder, signature.args[0], args[0], args[1])
            builder.store(args[2], builder.bitcast(pointer, args[2].type.as_pointer()), align=8)
            return context.get_dummy_value()

        return types.none(array, start, value), codegen

    store.__doc__ = doc
    return intrinsic(store)


def _element_pointer(context, builder, array_type, array, index):
    ary = context.make_array(array_type)(context, builder, array)
    return builder.gep(ary.data, [index])


load_lanes = _vector_load(lanes_type, "array[start:start + 8] of a C-contiguous float64 array (the caller keeps "
                                      "it in bounds).")
store_lanes = _vector_store(lanes_type, "array[start:start + 8] = value (C-contiguous float64; the caller keeps "
                                        "it in bounds).")


@intrinsic
def all_lanes(typingctx):
    """A mask that holds in every lane."""
    return mask_type(), lambda context, builder, signature, args: ir.Constant(_MASK, [1] * WIDTH)


@intrinsic
def select_tuple(typingctx, mask, new, old):
    """Lane by lane, element by element: ``new`` where ``mask`` holds, else ``old`` (tuples of equal
    length whose elements are Lanes or numbers; numbers broadcast); a tuple of Lanes."""
    if not (mask == mask_type and isinstance(new, types.BaseTuple) and isinstance(old, types.BaseTuple)
            and len(new) == len(old) and all(_is_lanes_operand(t) for t in (*new, *old))):
        return None
    result_type = types.UniTuple(lanes_type, len(new))

    def codegen(context, builder, signature, args):
        result = ir.Constant(context.get_value_type(result_type), ir.Undefined)
        for i in range(len(new)):
            x = _as_vector(context, builder, builder.extract_value(args[1], i), new[i])
            y = _as_vector(context, builder, builder.extract_value(args[2], i), old[i])
            result = builder.insert_value(result, builder.select(args[0], x, y), i)
        return result

    return result_type(mask, new, old), codegen


def choose(condition, if_true, if_false):
    """``if_true if condition else if_false`` for a bool, :func:`select` for a ``LaneMask`` (compiled code
    only): one spelling of a two-way choice in kernels compiled for floats and for Lanes."""
    raise NotImplementedError("choose is for compiled code")


@overload(choose)
def _overload_choose(condition, if_true, if_false):
    if isinstance(condition, types.Boolean):
        return lambda condition, if_true, if_false: if_true if condition else if_false
    if condition == mask_type:
        return lambda condition, if_true, if_false: select(condition, if_true, if_false)
    return None


def constant_like(template, value):
    """``value`` in the form of ``template``: a double, or ``Lanes`` with it in every lane (compiled code only)."""
    raise NotImplementedError("constant_like is for compiled code")


@overload(constant_like)
def _overload_constant_like(template, value):
    if template == lanes_type:
        return lambda template, value: broadcast(value)
    if isinstance(template, types.Float):
        return lambda template, value: float(value)
    return None


@overload(max)
def _overload_max(*values):
    # Python's max: the first value unless a later one is larger (so a NaN never replaces a number)
    if len(values) == 1 and isinstance(values[0], types.BaseTuple):
        values = tuple(values[0])
    if not (len(values) in (2, 3) and all(v == lanes_type for v in values)):
        return None
    if len(values) == 2:
        return lambda *values: select(values[1] > values[0], values[1], values[0])

    def max3(*values):
        first = select(values[1] > values[0], values[1], values[0])
        return select(values[2] > first, values[2], first)

    return max3


@intrinsic
def lane_of(typingctx, values, lane):
    """The doubles of one lane of a tuple of Lanes (a tuple of floats)."""
    if not (isinstance(values, types.UniTuple) and values.dtype == lanes_type and isinstance(lane, types.Integer)):
        return None
    result_type = types.UniTuple(types.float64, values.count)

    def codegen(context, builder, signature, args):
        result = ir.Constant(context.get_value_type(result_type), ir.Undefined)
        for i in range(values.count):
            result = builder.insert_value(result, builder.extract_element(builder.extract_value(args[0], i), args[1]), i)
        return result

    return result_type(values, lane), codegen


# ---------------------------------------------------------------------------------------------
# Quad: four doubles, for one state's quaternions and 3-vectors (a 3-vector's fourth lane is zero).


@intrinsic
def quad(typingctx, a, b, c, d):
    """The four numbers (a, b, c, d) as one Quad; with a Lanes among them (one value per member), the
    QuadLanes of the four components (numbers in every member)."""
    if any(t == lanes_type for t in (a, b, c, d)) and all(_is_lanes_operand(t) for t in (a, b, c, d)):
        def wide(context, builder, signature, args):
            parts = [_as_vector(context, builder, v, t) for v, t in zip(args, signature.args)]
            first = builder.shuffle_vector(parts[0], parts[1], ir.Constant(ir.VectorType(ir.IntType(32), 16),
                                                                           list(range(16))))
            second = builder.shuffle_vector(parts[2], parts[3], ir.Constant(ir.VectorType(ir.IntType(32), 16),
                                                                            list(range(16))))
            return builder.shuffle_vector(first, second, ir.Constant(ir.VectorType(ir.IntType(32), 32),
                                                                     list(range(32))))

        return quad_lanes_type(a, b, c, d), wide
    if not all(isinstance(t, (types.Float, types.Integer)) for t in (a, b, c, d)):
        return None

    def codegen(context, builder, signature, args):
        vector = ir.Constant(_QUAD, ir.Undefined)
        for i, (value, value_type) in enumerate(zip(args, signature.args)):
            scalar = context.cast(builder, value, value_type, types.float64)
            vector = builder.insert_element(vector, scalar, ir.Constant(ir.IntType(32), i))
        return vector

    return quad_type(a, b, c, d), codegen


@intrinsic
def quad_lane(typingctx, value, lane):
    """One lane of a Quad, as a double; of a QuadLanes, one component of every member (Lanes)."""
    if not isinstance(lane, types.Integer):
        return None
    if value == quad_lanes_type:
        def component(context, builder, signature, args):
            out = ir.Constant(_VECTOR, ir.Undefined)
            first = builder.mul(context.cast(builder, args[1], signature.args[1], types.int32),
                                ir.Constant(ir.IntType(32), WIDTH))
            for member in range(WIDTH):
                element = builder.extract_element(args[0], builder.add(first, ir.Constant(ir.IntType(32), member)))
                out = builder.insert_element(out, element, ir.Constant(ir.IntType(32), member))
            return out

        return lanes_type(value, lane), component
    if value != quad_type:
        return None
    return types.float64(value, lane), lambda context, builder, signature, args: builder.extract_element(*args)


def quad_shuffle(indices):
    """An intrinsic returning its Quad argument with lane i taken from lane ``indices[i]`` (0–3), or 0.0
    where ``indices[i]`` is 4: a permutation fixed when the kernel compiles (one shuffle instruction)."""
    if len(indices) != QUAD_WIDTH or not all(i in range(QUAD_WIDTH + 1) for i in indices):
        raise ValueError(f"indices: expected four lanes in 0..4, got {indices!r}.")
    mask = ir.Constant(ir.VectorType(ir.IntType(32), QUAD_WIDTH), list(indices))
    # on a QuadLanes the same permutation of the components, every member alike (4 → the zeros' vector)
    wide = [i * WIDTH + lane for i in indices for lane in range(WIDTH)]
    mask_wide = ir.Constant(ir.VectorType(ir.IntType(32), QUAD_WIDTH * WIDTH), wide)

    @intrinsic
    def shuffle(typingctx, value):
        if value not in (quad_type, quad_lanes_type):
            return None
        vector, chosen = (_QUAD, mask) if value == quad_type else (_QUAD_LANES, mask_wide)

        def codegen(context, builder, signature, args):
            return builder.shuffle_vector(args[0], ir.Constant(vector, [0.0] * vector.count), chosen)

        return value(value), codegen

    return shuffle


def _is_member_rows(t):
    """A two-dimensional C-contiguous float64 array of rows of eight members: row i is one quantity."""
    return isinstance(t, types.Array) and t.dtype == types.float64 and t.ndim == 2 and t.layout == "C"


@intrinsic
def load_quad(typingctx, array, start):
    """array[start:start + 4] of a C-contiguous float64 array as a Quad, or of member rows (n, 8) as the
    QuadLanes of rows start … start + 3 (the caller keeps it in bounds)."""
    if not isinstance(start, types.Integer):
        return None
    vector_type = quad_type if _is_vector_array(array) else quad_lanes_type if _is_member_rows(array) else None
    if vector_type is None:
        return None

    def codegen(context, builder, signature, args):
        pointer = _row_pointer(context, builder, signature.args[0], *args)
        vector = ir.VectorType(ir.DoubleType(), vector_type.width)
        return builder.load(builder.bitcast(pointer, vector.as_pointer()), align=8)

    return vector_type(array, start), codegen


@intrinsic
def store_quad(typingctx, array, start, value):
    """array[start:start + 4] = value (Quad, C-contiguous float64), or rows start … start + 3 of member
    rows (n, 8) = value (QuadLanes); the caller keeps it in bounds."""
    if not (isinstance(start, types.Integer) and ((_is_vector_array(array) and value == quad_type)
                                                  or (_is_member_rows(array) and value == quad_lanes_type))):
        return None

    def codegen(context, builder, signature, args):
        pointer = _row_pointer(context, builder, signature.args[0], args[0], args[1])
        builder.store(args[2], builder.bitcast(pointer, args[2].type.as_pointer()), align=8)
        return context.get_dummy_value()

    return types.none(array, start, value), codegen


def _row_pointer(context, builder, array_type, array, index):
    """Pointer to element ``index`` of a 1-d array, or to row ``index`` of member rows (n, 8)."""
    if array_type.ndim == 2:
        index = builder.mul(index, ir.Constant(index.type, WIDTH))
    return _element_pointer(context, builder, array_type, array, index)


@intrinsic
def load_member_row(typingctx, array, index):
    """Row ``index`` of member rows (n, 8) as Lanes: one quantity of eight members (in bounds)."""
    if not (_is_member_rows(array) and isinstance(index, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        pointer = _row_pointer(context, builder, signature.args[0], *args)
        return builder.load(builder.bitcast(pointer, _VECTOR.as_pointer()), align=8)

    return lanes_type(array, index), codegen


@intrinsic
def store_member_row(typingctx, array, index, value):
    """Row ``index`` of member rows (n, 8) = value (Lanes; in bounds)."""
    if not (_is_member_rows(array) and isinstance(index, types.Integer) and value == lanes_type):
        return None

    def codegen(context, builder, signature, args):
        pointer = _row_pointer(context, builder, signature.args[0], args[0], args[1])
        builder.store(args[2], builder.bitcast(pointer, _VECTOR.as_pointer()), align=8)
        return context.get_dummy_value()

    return types.none(array, index, value), codegen


@intrinsic
def load_broadcast_quad(typingctx, array, index):
    """array[index] in every lane (C-contiguous float64, ``index`` in bounds: no wrap-around, a branch in an
    inner loop); of member rows (n, 8), row ``index`` (each member's value) in all four components."""
    if not isinstance(index, types.Integer):
        return None
    if _is_member_rows(array):
        def rows(context, builder, signature, args):
            pointer = _row_pointer(context, builder, signature.args[0], *args)
            row = builder.load(builder.bitcast(pointer, _VECTOR.as_pointer()), align=8)
            return _as_vector(context, builder, row, lanes_type, QUAD_WIDTH * WIDTH)

        return quad_lanes_type(array, index), rows
    if not _is_vector_array(array):
        return None

    def codegen(context, builder, signature, args):
        pointer = _element_pointer(context, builder, signature.args[0], *args)
        return _splat(builder, builder.load(pointer, align=8), QUAD_WIDTH)

    return quad_type(array, index), codegen
