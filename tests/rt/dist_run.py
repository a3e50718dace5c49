"""tests/dist/run as a module, for the RT guest's distributed cases
(tests/rt/netem, tests/rt/can-dist): its network namespace, its runs of the
HLC and the LLCs and its trace check. run-all runs no file with a dot in
its name, so this one is only imported."""
import importlib.machinery
import importlib.util
import os
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def load():
    path = os.path.join(ROOT, "tests", "dist", "run")
    # no __pycache__ beside it in the shared tree for a file run as a script
    sys.dont_write_bytecode = True
    loader = importlib.machinery.SourceFileLoader("dist_run_script", path)
    spec = importlib.util.spec_from_loader("dist_run_script", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod
