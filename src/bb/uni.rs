//! Univariate Bernstein polynomials on [0, 1]: evaluation, subdivision, product, first root.
