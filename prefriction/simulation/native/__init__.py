"""The native driver of unforced runs: the model's generated C code driven by a C Runge-Kutta 5(4).

:func:`~prefriction.simulation.native.library.native_driver` builds it once per model
structure; :func:`~prefriction.simulation.native.advance.advance_native` runs it
(``docs/simulator.md#native``).
"""
