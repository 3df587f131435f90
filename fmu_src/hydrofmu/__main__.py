"""``python -m hydrofmu``: the ``hydrofmu`` command."""
import sys

from .cli import main

sys.exit(main())
