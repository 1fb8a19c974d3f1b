"""sahara: render scenes and cast rays into meshes from Python."""
from ._sahara import *  # noqa: F401,F403
