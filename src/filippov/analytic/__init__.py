"""The paper's closed forms and asymptotic formulas, independent of the solver."""
