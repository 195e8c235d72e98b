"""Scene descriptions, one module per problem kind; importing registers them."""
from . import manufactured  # noqa: F401
from . import cell  # noqa: F401
from . import macro  # noqa: F401
from . import direct  # noqa: F401
