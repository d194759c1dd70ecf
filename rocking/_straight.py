"""Straight-line arithmetic compiled straight to LLVM IR (for the generated Taylor steps).

The unrolled Taylor steps (:mod:`rocking._taylor_fixed`) are hundreds of assignments of float
arithmetic each.  Compiling them the ordinary numba way types and lowers every statement in
Python: about 1 s per step function on this machine, most of the solver's first-run compile time.
:func:`straight` instead reads the step's Python source (kept as the reference: it runs as plain
Python too) and emits the same operations, in the same order and on the same types, as LLVM
instructions through a numba intrinsic: the same instructions numba would emit (``fmul``,
``fadd``, ``fsub``, negation as ``fsub -0.0, x``, ``abs`` as ``llvm.fabs``, ordered comparisons),
so the compiled step gives the same bits as numba's own compilation of that source (compared on
2000 random steps of every order when this was written; ``tests/test_solver.py`` checks the
compiled steps against the plain Python evaluation of their source), in a few milliseconds of
code generation instead of about a second.

The accepted subset is what ``rocking/_make_taylor.py`` writes: assignments to names of float
expressions (``+ - *``, unary ``-``, ``abs``, float constants, the float parameters, ``U[k]`` reads
of an array parameter at a constant index), stores ``cf[k] = expr`` (inside ``if store:`` or not),
an integer ``flag`` set by ``if``/``elif`` on comparisons joined by ``and``/``or``, and a final
``return`` of a tuple of floats and ``flag``.  Anything else raises ``NotImplementedError`` when
the step is compiled.
"""
from __future__ import annotations

import ast
import inspect
import textwrap

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

_DOUBLE = ir.DoubleType()
_I64 = ir.IntType(64)
_CMP = {ast.Gt: ">", ast.GtE: ">=", ast.Lt: "<", ast.LtE: "<=", ast.Eq: "==", ast.NotEq: "!="}


def _function_def(py_func):
    tree = ast.parse(textwrap.dedent(inspect.getsource(py_func)))
    fn = tree.body[0]
    assert isinstance(fn, ast.FunctionDef)
    return fn


def _return_types(fn):
    ret = fn.body[-1]
    if not (isinstance(ret, ast.Return) and isinstance(ret.value, ast.Tuple)):
        raise NotImplementedError("the step must end with 'return a, b, ...'")
    return tuple(types.int64 if isinstance(e, ast.Name) and e.id == "flag" else types.float64
                 for e in ret.value.elts)


class _Emitter:
    """Walks the function's statements, emitting LLVM instructions with ``builder``."""

    def __init__(self, context, builder, env, arrays):
        self.context, self.builder = context, builder
        self.env = env          # name -> llvm value (double, i64 or i1)
        self.arrays = arrays    # name -> (array type, array struct)

    # ----------------------------------------------------------------- expressions
    def expr(self, node):
        b = self.builder
        if isinstance(node, ast.Name):
            return self.env[node.id]
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool):
                return ir.Constant(ir.IntType(1), int(node.value))
            if isinstance(node.value, int):
                return ir.Constant(_I64, node.value)
            return ir.Constant(_DOUBLE, float(node.value))
        if isinstance(node, ast.BinOp):
            x, y = self.double(node.left), self.double(node.right)
            if isinstance(node.op, ast.Add):
                return b.fadd(x, y)
            if isinstance(node.op, ast.Sub):
                return b.fsub(x, y)
            if isinstance(node.op, ast.Mult):
                return b.fmul(x, y)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return b.fsub(ir.Constant(_DOUBLE, -0.0), self.double(node.operand))
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id == "abs" and len(node.args) == 1):
            x = self.double(node.args[0])
            fabs = b.module.declare_intrinsic("llvm.fabs", [x.type])
            return b.call(fabs, [x])
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name):
            return b.load(self.pointer(node))
        if isinstance(node, ast.Compare) and len(node.ops) == 1:
            return b.fcmp_ordered(_CMP[type(node.ops[0])], self.double(node.left),
                                  self.double(node.comparators[0]))
        if isinstance(node, ast.BoolOp):
            values = [self.expr(v) for v in node.values]
            out = values[0]
            for v in values[1:]:
                out = b.or_(out, v) if isinstance(node.op, ast.Or) else b.and_(out, v)
            return out
        raise NotImplementedError(f"straight: unsupported expression {ast.dump(node)[:80]}")

    def double(self, node):
        value = self.expr(node)
        if value.type == _I64:
            return self.builder.sitofp(value, _DOUBLE)
        return value

    def pointer(self, node):
        aryty, ary = self.arrays[node.value.id]
        index = node.slice
        if not (isinstance(index, ast.Constant) and isinstance(index.value, int)):
            raise NotImplementedError("straight: arrays are indexed by constants only")
        return cgutils.get_item_pointer2(
            self.context, self.builder, data=ary.data, shape=cgutils.unpack_tuple(self.builder, ary.shape),
            strides=cgutils.unpack_tuple(self.builder, ary.strides), layout=aryty.layout,
            inds=[ir.Constant(_I64, index.value)])

    # ----------------------------------------------------------------- statements
    def statements(self, body):
        for node in body:
            if isinstance(node, ast.Return):
                return [self.expr(e) for e in node.value.elts]
            self.statement(node)
        return None

    def statement(self, node):
        b = self.builder
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            return  # a docstring
        if isinstance(node, ast.Assign) and len(node.targets) == 1:
            target = node.targets[0]
            if isinstance(target, ast.Name):
                self.env[target.id] = self.expr(node.value)
                return
            if isinstance(target, ast.Subscript):
                b.store(self.double(node.value), self.pointer(target))
                return
        if isinstance(node, ast.If):
            stores = any(isinstance(t, ast.Subscript) for s in ast.walk(node)
                         if isinstance(s, ast.Assign) for t in s.targets)
            cond = self.expr(node.test)
            if stores:  # side effects: a real branch
                if node.orelse:
                    raise NotImplementedError("straight: 'else' around stores")
                with b.if_then(cond):
                    self.statements(node.body)
                return
            # assignments only: both sides evaluated, then one value chosen (same values)
            before = dict(self.env)
            self.statements(node.body)
            taken = self.env
            self.env = dict(before)
            self.statements(node.orelse)
            for name in set(taken) | set(self.env):
                if taken.get(name) is not self.env.get(name):
                    if name not in taken or name not in self.env:
                        raise NotImplementedError(f"straight: {name} set on one side only")
                    self.env[name] = b.select(cond, taken[name], self.env[name])
            return
        raise NotImplementedError(f"straight: unsupported statement {ast.dump(node)[:80]}")


def straight(py_func):
    """A numba intrinsic computing ``py_func`` (a function of the subset above) as one block of
    LLVM instructions; call it from an ``@njit`` function with the same arguments."""
    names = list(inspect.signature(py_func).parameters)
    parsed = []  # the source is read when the step is first compiled, not at import

    def define(args):
        if not parsed:
            parsed.append(_function_def(py_func))
        fn = parsed[0]
        sig = types.Tuple(_return_types(fn))(*args)

        def codegen(context, builder, signature, values):
            env, arrays = {}, {}
            for name, ty, value in zip(names, signature.args, values):
                if isinstance(ty, types.Array):
                    arrays[name] = (ty, context.make_array(ty)(context, builder, value))
                elif isinstance(ty, types.Omitted):  # a default left out: its constant
                    env[name] = ir.Constant(ir.IntType(1), int(bool(ty.value)))
                elif isinstance(ty, types.Boolean):
                    env[name] = context.cast(builder, value, ty, types.boolean)
                elif isinstance(ty, types.Float):
                    env[name] = context.cast(builder, value, ty, types.float64)
                elif isinstance(ty, types.Integer):
                    env[name] = context.cast(builder, value, ty, types.int64)
                else:
                    raise NotImplementedError(f"straight: argument {name} of type {ty}")
            out = _Emitter(context, builder, env, arrays).statements(fn.body)
            return context.make_tuple(builder, signature.return_type, out)

        return sig, codegen

    # numba reads the intrinsic's parameters from its signature: spelled out, not *args
    params = ", ".join(names)
    namespace = {"define": define}
    exec(f"def {py_func.__name__}_ir(typingctx, {params}):\n    return define(({params},))",
         namespace)
    return intrinsic(namespace[f"{py_func.__name__}_ir"])
