"""G-code posts: toolpath IR in, program text out (no file I/O of its own)."""

from spur_cad.dialects import DIALECTS, Dialect, dialect
from spur_cad.post.program import PostedProgram, ProgramInfo, post_program
from spur_cad.post.settings import PostError, PostSettings

DIALECT_NAMES = tuple(DIALECTS)

__all__ = ["DIALECTS", "DIALECT_NAMES", "Dialect", "PostError", "PostSettings", "PostedProgram", "ProgramInfo",
           "dialect", "post_program"]
