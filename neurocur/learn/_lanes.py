"""``dot4`` of the exact kernels, written as two-lane SIMD code.

``_kernels.dot4`` defines its sums as two partial sums each, one over the even and one
over the odd indices, taken in order and added at the end. That order is what the
float64 results are reproducible to, so the compiler may not reorder it, and numba
compiles the scalar loop as it stands (its SLP vectoriser is off). Here the same order
is emitted directly in LLVM IR: the even and odd partial sums are the two lanes of one
``<2 x double>`` vector, so each lane performs exactly the scalar loop's multiplies and
adds (no fused multiply-add, no reassociation) and the results are bit-identical, while
the four sums advance together, half as many instructions.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

_F64 = ir.DoubleType()
_PAIR = ir.VectorType(_F64, 2)
_LANE = (ir.Constant(ir.IntType(32), 0), ir.Constant(ir.IntType(32), 1))


def _contiguous_float64(*arrays) -> bool:
    return all(isinstance(a, types.Array) and a.ndim == 1 and a.layout == "C" and a.dtype == types.float64
               for a in arrays)


@intrinsic
def dot4_lanes(typingctx, v, r, x):
    """(v·r, r·r, v·x, r·x) of three C-contiguous float64 vectors of equal length, each
    as an even-index and an odd-index partial sum (an odd last element joins the even
    one), added at the end."""
    if not _contiguous_float64(v, r, x):
        return None

    def codegen(context, builder, signature, args):
        arrays = [context.make_array(t)(context, builder, a) for t, a in zip(signature.args, args)]
        data = [a.data for a in arrays]
        n = builder.extract_value(arrays[0].shape, 0)
        even = builder.and_(n, ir.Constant(n.type, -2))
        sums = [cgutils.alloca_once_value(builder, ir.Constant(_PAIR, [0.0, 0.0])) for _ in range(4)]

        def accumulate(values, update):
            vv, rr, xx = values
            for slot, (p, q) in zip(sums, ((vv, rr), (rr, rr), (vv, xx), (rr, xx))):
                builder.store(update(builder.load(slot), builder.fmul(p, q)), slot)

        step = ir.Constant(n.type, 2)
        with cgutils.for_range_slice(builder, ir.Constant(n.type, 0), even, step) as (d, _):
            pairs = [builder.load(builder.bitcast(builder.gep(p, [d]), _PAIR.as_pointer()), align=8) for p in data]
            accumulate(pairs, builder.fadd)
        with builder.if_then(builder.icmp_signed("<", even, n)):
            last = [builder.load(builder.gep(p, [even])) for p in data]
            accumulate(last, lambda acc, term: builder.insert_element(
                acc, builder.fadd(builder.extract_element(acc, _LANE[0]), term), _LANE[0]))
        out = []
        for slot in sums:
            pair = builder.load(slot)
            out.append(builder.fadd(builder.extract_element(pair, _LANE[0]), builder.extract_element(pair, _LANE[1])))
        return context.make_tuple(builder, signature.return_type, out)

    return types.UniTuple(types.float64, 4)(v, r, x), codegen
