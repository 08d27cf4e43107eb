# expect: rejected
import subprocess
subprocess.run(["touch", "@MARKER@/subprocess"])
