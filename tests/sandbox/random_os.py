# expect: rejected
import random
random._os.system("touch @MARKER@/random_os")
