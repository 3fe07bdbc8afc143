import sys

from gaitval.cli import main

sys.exit(main())
