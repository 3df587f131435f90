"""Build the FMUs of every scene in models/ (or of the scene files given):

    python build_fmus.py [SCENE ...] [-o OUTDIR]

One subfolder per scene in OUTDIR (default build/fmus), with the FMUs, manifest.json and
OspSystemStructure.xml.  Same as ``hydrofmu build``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "fmu_src"))  # works without an install too
from hydrofmu.cli import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main(["build", *sys.argv[1:]]))
