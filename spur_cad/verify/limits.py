"""The limits of `spur-cad verify`'s program reader (spur_cad.verify.reader): the largest program read, and
what reading it may do. Together they bound a verification to about a minute and half a gigabyte whatever the
program holds (docs/verification.md, "Limits")."""

MAX_PROGRAM_BYTES = 64 * 1024 * 1024  # refused at once beyond this, naming the size
MAX_LINE_CHARS = 4096  # controllers take 128-256 characters a block
MAX_LINES = 20_000_000  # lines in the file (blank and comment lines included)
MAX_LINES_READ = 40_000_000  # lines read while executing (loop bodies and subprograms each time they run)
MAX_MOVES = 2_000_000  # moves recorded (about 60 bytes each)
MAX_BLOCKS = 8_000_000  # blocks executed (loops and calls counted)
MAX_CHARACTERS_READ = 100_000_000  # characters read while executing (long blocks of many words cost more)
MAX_SUBPROGRAMS = 100_000  # subprograms, loops and labels defined
MAX_VARIABLES = 10_000  # distinct variables set (LinuxCNC has 5,400 numbered parameters)
MAX_CALL_DEPTH = 8
MAX_REPEAT = 100_000
# A directed move (Okuma M15/M16) to an angle this close to where A is moves 0: far below the finest A word a
# dialect writes (4 decimals, 1e-4 deg; 1e-6 deg is 1.7 nm at 100 mm radius) and far above the rounding of
# an unwound angle (about 1e-13 deg at 10,000 deg), which made such a move a spurious full turn.
DIRECTED_TOLERANCE_DEG = 1e-6
CHECK_EVERY_BLOCKS = 100_000  # how often a long read calls its checkpoint (the CLI stops there on a signal)
LOCAL_VARIABLES = 33  # #1..#33: a call's arguments, restored when it returns
