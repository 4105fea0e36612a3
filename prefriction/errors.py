"""Exceptions raised by prefriction."""

from __future__ import annotations


class PrefrictionError(Exception):
    """Base class of every error raised by prefriction itself."""


class SolverError(PrefrictionError, RuntimeError):
    """An integration failed; the message names the time, the state and what to try."""
