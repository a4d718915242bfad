"""calcvar._interp — the solution between the nodes, from a Solution's own arrays.

On each element the solution is the polynomial of the element's degree p through its p+1
Gauss-Lobatto-Legendre nodes (docs/theory.md, E-1), the interpolant cv_solver_eval
evaluates in C. Here it is evaluated in numpy from the nodes and nodal values a Solution
owns (so a copied, unpickled or shared Solution needs no C state): the Lagrange basis in
product form (exact at the nodes, no division by x - x_j), and y' as the interpolant of
the nodal derivatives (the differentiation matrix of the same nodes; exact, since y' is a
polynomial of degree p - 1). A point on an element boundary belongs to the element on its
right (the last element for b), as in cv_solver_eval.
SPDX-License-Identifier: MIT
"""
import numpy as np


class Interpolant:
    """The piecewise polynomial through x (nodes,), values (nodes, n) with element degrees."""

    def __init__(self, x, values, degrees):
        self.x = x
        self.values = values
        self.degrees = np.asarray(degrees, dtype=int)
        self.first = np.concatenate(([0], np.cumsum(self.degrees)))  # node of each boundary
        self.xe = x[self.first]
        self._tables = {}

    def _table(self, p):
        """Per element of degree p: its node indices, barycentric weights, and nodal
        derivatives of the values."""
        if p not in self._tables:
            elems = np.flatnonzero(self.degrees == p)
            idx = self.first[elems, None] + np.arange(p + 1)
            X = self.x[idx]                                   # (k, p+1)
            diff = X[:, :, None] - X[:, None, :]
            diff[:, np.arange(p + 1), np.arange(p + 1)] = 1.0
            w = 1.0 / np.prod(diff, axis=2)                   # w_j = 1 / prod_{k!=j} (x_j - x_k)
            D = (w[:, None, :] / w[:, :, None]) / diff        # D_ij = (w_j / w_i) / (x_i - x_j)
            D[:, np.arange(p + 1), np.arange(p + 1)] = 0.0
            D[:, np.arange(p + 1), np.arange(p + 1)] = -D.sum(axis=2)
            dY = np.einsum("kij,kjn->kin", D, self.values[idx])
            self._tables[p] = (np.full(len(self.degrees), -1), idx, w, dY)
            self._tables[p][0][elems] = np.arange(len(elems))
        return self._tables[p]

    def __call__(self, t, derivative=False):
        """y (n, m) at the m points t (inside [a, b]), and y' when derivative is true."""
        n, m = self.values.shape[1], t.size
        y = np.empty((n, m))
        dy = np.empty((n, m)) if derivative else None
        e = np.clip(np.searchsorted(self.xe, t, side="right") - 1, 0, len(self.degrees) - 1)
        pe = self.degrees[e]
        for p in np.unique(pe):
            sel = np.flatnonzero(pe == p)
            row, idx, w, dY = self._table(int(p))
            r = row[e[sel]]
            d = t[sel, None] - self.x[idx[r]]                 # (k, p+1)
            left = np.ones_like(d)
            right = np.ones_like(d)
            left[:, 1:] = np.cumprod(d[:, :-1], axis=1)
            right[:, :-1] = np.cumprod(d[:, :0:-1], axis=1)[:, ::-1]
            L = left * right * w[r]                           # Lagrange basis at t
            y[:, sel] = np.einsum("kj,kjn->nk", L, self.values[idx[r]])
            if derivative:
                dy[:, sel] = np.einsum("kj,kjn->nk", L, dY[r])
        return y, dy
