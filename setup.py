"""`pip install --no-build-isolation .` from the repository root builds the
pneumid Python module; the build logic lives in python/setup.py."""
import pathlib
import runpy

runpy.run_path(str(pathlib.Path(__file__).resolve().parent / "python" / "setup.py"),
               run_name="__main__")
