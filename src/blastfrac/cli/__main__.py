"""python -m blastfrac.cli"""

import sys

from . import main

sys.exit(main())
