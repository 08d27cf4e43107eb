# expect: rejected
import sys
sys.setrecursionlimit(10 ** 6)

def down(n):
    return down(n + 1)

down(0)
