"""``python -m ballc`` is the ``ballc`` command."""
import sys

from .cli import main

sys.exit(main())
