"""The application: scenario files, running a scenario end to end, the command line.

* :mod:`poinsot.app.scenario` reads and checks a scenario file (``docs/scenarios.md``) into a
  scenario object; :mod:`poinsot.app.scenario_reference` renders every key it accepts;
* :mod:`poinsot.app.runs` holds one run object per kind of scenario (rigid body, Lagrangian
  system, ensemble, motion relative to a carrier), chosen once by the scenario's type, each
  with the same interface: simulate, summarise, write data, figures and the report;
* :mod:`poinsot.app.job` runs any of them into an output folder, atomically, in one sequence;
* :mod:`poinsot.app.cli` is the ``poinsot`` command (``python -m poinsot``).

The application sits on top: it imports the presentation (:mod:`poinsot.viz`) and the library;
neither imports it (the ``layers`` contract in ``pyproject.toml``).
"""
