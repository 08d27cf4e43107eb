# expect: rejected
import sys
sys.settrace(None)
while True:
    pass
