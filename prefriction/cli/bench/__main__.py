"""``python -m prefriction.cli.bench``: the same as ``prefriction bench``."""

import sys

from prefriction.cli.bench import main

sys.exit(main())
