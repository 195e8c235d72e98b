"""``python -m ngcontact ...``: the command line of :mod:`ngcontact.cli`, for an interpreter without the script."""
import sys

from ngcontact.cli import main

if __name__ == "__main__":
    sys.exit(main())
