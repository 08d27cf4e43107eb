# expect: rejected
import ctypes
ctypes.CDLL(None).system(b"touch @MARKER@/ctypes")
