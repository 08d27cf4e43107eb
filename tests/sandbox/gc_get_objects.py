# expect: rejected
import gc
for obj in gc.get_objects():
    pass
