"""The kernel layer: plain-array functions under poinsot's classes.

Rule (checked by ``tests/test_layering.py``): modules in ``poinsot.kernels`` import only NumPy,
the standard library, optional numba, and each other — never anything from the layers above.
They take and return arrays, validate nothing, do no I/O, and are written in the NumPy subset
that numba compiles.
"""
