"""``python -m prefriction.cli``: the ``prefriction`` command."""

from prefriction.cli import main

raise SystemExit(main())
