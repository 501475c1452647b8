"""UFL's expression hash data, computed with fewer Python steps and shared between the forms
of one model: the same bytes as UFL 2022.2's own.

UFL names every compiled form and expression by a SHA-512 hash of its expression DAG
(``ufl.algorithms.signature.compute_expression_hashdata``): each node's digest is the hash of
``str([typecode, digest of operand 1, ...])`` (a terminal's: ``str([its hash data])``),
children before parents. In a small run that is a quarter of the time: its traversal keeps a
set of visited nodes (a Python ``__hash__`` per look-up) and spells each operand's 64-byte
digest anew for every parent.

:func:`compute_expression_hashdata` computes the same digests over the same DAG:

* nodes are told apart by identity, not by UFL's structural equality, so a node that is
  equal to another but not the same object is hashed again, to the same digest (a digest is
  a function of the node's structure and its terminals' hash data only);
* each node's digest is spelt once (``repr``), and a parent's text is joined from the
  spellings exactly as ``str`` of the list spells it (``"[" + ", ".join(reprs) + "]"``);
* the digests of one form's nodes are kept (by identity, weakly) for the next form: the
  tangent J = dF/dw of a model contains its residual's integrands, whose digests are reused
  when every terminal of the residual has the same hash data in the tangent (UFL numbers
  coefficients, arguments and indices per form, so this is checked, term by term; otherwise
  nothing is reused). Nothing is kept alive by it.

Before the hashing, a form is traversed for its terminals three times (its coefficients and
arguments, its constants, the terminals' hash data) and an expression five times; UFL
expressions are immutable, so :func:`unique_terminals` lists a node's terminals once and
answers the next traversal of the same node from that list (the same terminals in the same
order), for as long as the node lives.
"""

import hashlib
import weakref
from functools import partial

#: node id -> (weak reference to the node, its unique terminals in traversal order)
_terminals = {}
#: UFL's modules that traverse terminals on the way to a signature
_TRAVERSING = ("ufl.algorithms.analysis", "ufl.algorithms.signature", "ufl.domain")

#: what the last call left for the next one: [terminals [(ref, hash data)], {id: (ref, digest,
#: spelling)}], or None
_carried = [None]


def install():
    """Give UFL's signature module :func:`compute_expression_hashdata` (form and expression
    signatures call it by its module name). Idempotent; ``.original`` is UFL's."""
    from ufl.algorithms import signature

    if signature.compute_expression_hashdata is compute_expression_hashdata:
        return
    compute_expression_hashdata.original = signature.compute_expression_hashdata
    signature.compute_expression_hashdata = compute_expression_hashdata
    import importlib

    from ufl.corealg import traversal

    unique_terminals.original = traversal.traverse_unique_terminals
    for name in _TRAVERSING:
        importlib.import_module(name).traverse_unique_terminals = unique_terminals


def unique_terminals(expr, visited=None):
    """UFL's ``traverse_unique_terminals``: the terminals of ``expr``, each once (by UFL's
    equality), in UFL's order; listed at the first call for a node and kept while it lives
    (a weak reference removes them with it). With ``visited`` given, UFL's own traversal."""
    if visited is not None or expr._ufl_is_terminal_:  # a terminal's list would hold it
        return unique_terminals.original(expr, visited)
    key = id(expr)
    entry = _terminals.get(key)
    if entry is None or entry[0]() is not expr:
        found = list(unique_terminals.original(expr))
        try:
            ref = weakref.ref(expr, partial(_forget, _terminals, key))
        except TypeError:  # no weak references: not kept
            return iter(found)
        entry = _terminals[key] = (ref, found)
    return iter(entry[1])


def _forget(table, key, ref):
    """Drop the terminals of a node that died from ``table`` (unless its id names a newer
    node already). The table is bound, not looked up: at exit module globals are gone."""
    entry = table.get(key)
    if entry is not None and entry[0] is ref:
        del table[key]


def compute_expression_hashdata(expression, terminal_hashdata):
    """The digest (bytes) of ``expression`` with the terminals' ``terminal_hashdata`` (as
    UFL's ``compute_expression_hashdata``: see the module doc)."""
    known = _reusable(terminal_hashdata)
    spelt = _digests(expression, terminal_hashdata, known)
    try:
        terms = [(weakref.ref(t), data) for t, data in terminal_hashdata.items()]
    except TypeError:  # a terminal without weak references: keep nothing
        _carried[0] = None
    else:
        _carried[0] = (terms, known)
    return spelt


def _reusable(terminal_hashdata):
    """The digests of the last call, by node id, if every terminal it hashed has the same
    hash data in ``terminal_hashdata`` (a form's next integrand, or the tangent of the last
    form); else an empty dict."""
    carried = _carried[0]
    _carried[0] = None
    if carried is None:
        return {}
    terms, known = carried
    missing = object()
    for ref, data in terms:
        t = ref()
        if t is None or terminal_hashdata.get(t, missing) != data:
            return {}
    return known


def _digests(expression, terminal_hashdata, known):
    """Digest of ``expression``; every node's (ref, digest, spelling) put into ``known``."""
    sha512 = hashlib.sha512
    root = _entry(known, expression)
    if root is not None:
        return root[1]
    stack = [(expression, iter(expression.ufl_operands))]
    while stack:
        node, operands = stack[-1]
        for op in operands:
            if _entry(known, op) is None:
                stack.append((op, iter(op.ufl_operands)))
                break
        else:
            stack.pop()
            if node._ufl_is_terminal_:
                text = "[" + repr(terminal_hashdata[node]) + "]"
            else:
                parts = [repr(node._ufl_typecode_)]
                parts += [known[id(op)][2] for op in node.ufl_operands]
                text = "[" + ", ".join(parts) + "]"
            digest = sha512(text.encode("utf-8")).digest()
            known[id(node)] = (weakref.ref(node), digest, repr(digest))
    return known[id(expression)][1]


def _entry(known, node):
    """(ref, digest, spelling) of ``node`` in ``known`` if it is that very object, else None."""
    entry = known.get(id(node))
    return entry if entry is not None and entry[0]() is node else None
