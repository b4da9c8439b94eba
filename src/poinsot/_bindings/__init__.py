"""The library's one door to the compiled core, ``poinsot._core``: a thin, typed facade per
concept.

Each module here names the bindings of one concept (their types are the stub's,
``poinsot/_core.pyi``), and the library imports them from here: no other module imports
``poinsot._core``, except :mod:`poinsot.layout`, the facade of the core's memory layouts.
``tests/test_layering.py`` holds that, and that every binding belongs to exactly one facade.
The modules hold no code: arguments are checked by the library functions that call them.
"""
