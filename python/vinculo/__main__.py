"""``python -m vinculo``: the same command line as the ``vinculo`` script."""

from vinculo.cli import main

raise SystemExit(main())
