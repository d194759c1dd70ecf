"""Housner's rocking block: solvers (exact-where-possible, fast, reference) and design."""
from .block import ALPHA_PLASTIC, Block, eta_housner

__all__ = ["ALPHA_PLASTIC", "Block", "eta_housner"]
