"""``python -m puppetphone`` runs the same command line as the ``puppetphone`` script."""

import sys

from puppetphone.cli import main

sys.exit(main())
