"""LMI layer: the only part of hinfnav that imports cvxpy.

LMI blocks, conditioning and scaling, the solver strategy object and one
solve; the robust bounded real LMI for a fixed filter. Solutions are never
trusted here: :mod:`hinfnav.design` certifies them with :mod:`hinfnav.analysis`.
"""

from .blocks import gamma_index, lmi20_matrix, observer_lmi_matrix
from .conditioning import Prepared, pow2, prepare, prepare_uncertainty, state_scaling
from .polytopic import extended_h2_matrices, extended_hinf_positive, solve_polytopic_hinf
from .robust_brl import robust_bounded_real_lmi
from .lmi20 import lmi20_problem, solve_lmi
from .solve import INFEASIBLE, METHODS, SOLVERS, LMIProblem, Solution, SolverOptions, run_solver

__all__ = [
    "lmi20_matrix",
    "observer_lmi_matrix",
    "gamma_index",
    "Prepared",
    "prepare",
    "prepare_uncertainty",
    "state_scaling",
    "pow2",
    "SOLVERS",
    "METHODS",
    "INFEASIBLE",
    "SolverOptions",
    "Solution",
    "solve_lmi",
    "lmi20_problem",
    "LMIProblem",
    "run_solver",
    "robust_bounded_real_lmi",
    "extended_hinf_positive",
    "extended_h2_matrices",
    "solve_polytopic_hinf",
]
