"""One spelling of a kernel for one member and for eight in lanes: the choices that differ by form.

A kernel written on :mod:`spinorbit.core.math.lanes`' Quad helpers runs one member on flat arrays and
eight on member rows (``QuadLanes``). Where it keeps an integer per member (a series' truncation order)
or branches on one, the one-member form keeps an ``int`` and a Python branch, the eight-member form a
``Lanes`` of whole numbers and a mask; these helpers are that difference, so the kernel's source is one.
Each compiles to the plain integer expression for the one-member form (no cost there).
"""

from numba import types
from numba.extending import overload

from spinorbit.core.math.lanes import (
    WIDTH,
    any_lane,
    broadcast,
    lane_of,
    lanes_type,
    load_member_row,
    quad,
    store_member_row,
)


def load_one(array, index):
    """array[index] of a 1-d array; of member rows (n, 8), row ``index`` as Lanes (compiled code only)."""
    raise NotImplementedError("load_one is for compiled code")


def store_one(array, index, value):
    """array[index] = value; of member rows (n, 8), row ``index`` = value (Lanes; compiled code only)."""
    raise NotImplementedError("store_one is for compiled code")


def first_member(array, index):
    """array[index] of a 1-d array; of member rows (n, 8), member 0's (a value all members share, such as
    a perturber's kind; compiled code only)."""
    raise NotImplementedError("first_member is for compiled code")


def member_rows(series):
    """A series array as the rows the Quad helpers read: flat (one member, 2-d series) or member rows
    (n, 8) (eight members, 3-d series [order, column, member]); compiled code only."""
    raise NotImplementedError("member_rows is for compiled code")


def _is_rows(array):
    return isinstance(array, types.Array) and array.ndim == 2


@overload(load_one)
def _overload_load_one(array, index):
    if _is_rows(array):
        return lambda array, index: load_member_row(array, index)
    return lambda array, index: array[index]


@overload(first_member)
def _overload_first_member(array, index):
    if _is_rows(array):
        return lambda array, index: array[index, 0]
    return lambda array, index: array[index]


@overload(store_one)
def _overload_store_one(array, index, value):
    if _is_rows(array):
        def rows(array, index, value):
            store_member_row(array, index, value)

        return rows

    def element(array, index, value):
        array[index] = value

    return element


@overload(member_rows)
def _overload_member_rows(series):
    if isinstance(series, types.Array) and series.ndim == 3:
        return lambda series: series.reshape((series.shape[0] * series.shape[1], series.shape[2]))
    return lambda series: series.reshape(-1)


def quad_zero(array):
    """A zero Quad for a flat array, a zero QuadLanes for member rows (compiled code only)."""
    raise NotImplementedError("quad_zero is for compiled code")


def order_like(template, value):
    """The integer ``value`` as an int (``template`` a number) or in every lane (``template`` Lanes)."""
    raise NotImplementedError("order_like is for compiled code")


def largest(orders):
    """The int itself, or the largest of the lanes' whole numbers as an int."""
    raise NotImplementedError("largest is for compiled code")


def all_above(k, orders):
    """k > orders for an int; k above every lane's order for Lanes."""
    raise NotImplementedError("all_above is for compiled code")


def any_below(k, orders):
    """k < orders for an int; k below some lane's order for Lanes."""
    raise NotImplementedError("any_below is for compiled code")


@overload(quad_zero)
def _overload_quad_zero(array):
    if _is_rows(array):
        return lambda array: quad(broadcast(0.0), 0.0, 0.0, 0.0)
    return lambda array: quad(0.0, 0.0, 0.0, 0.0)


@overload(order_like)
def _overload_order_like(template, value):
    if template == lanes_type:
        return lambda template, value: broadcast(float(value))
    return lambda template, value: int(value)


@overload(largest)
def _overload_largest(orders):
    if orders == lanes_type:
        def lanes_largest(orders):
            top = lane_of((orders,), 0)[0]
            for lane in range(1, WIDTH):
                top = max(top, lane_of((orders,), lane)[0])
            return int(top)

        return lanes_largest
    return lambda orders: orders


@overload(all_above)
def _overload_all_above(k, orders):
    if orders == lanes_type:
        return lambda k, orders: not any_lane(orders >= k)
    return lambda k, orders: k > orders


@overload(any_below)
def _overload_any_below(k, orders):
    if orders == lanes_type:
        return lambda k, orders: any_lane(orders > k)
    return lambda k, orders: k < orders


__all__ = ["all_above", "any_below", "first_member", "largest", "load_one", "member_rows", "order_like", "quad_zero", "store_one"]
