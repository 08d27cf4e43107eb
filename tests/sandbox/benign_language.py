# expect: ok
# Ordinary Python a model writes: classes, closures, comprehensions, formatting, a main guard.
import math
from math import sqrt


class Step:
    name = ""
    args = ()


def make_step(name, args):
    step = Step()
    step.name = name
    step.args = args
    return step


def plan(objects):
    return [make_step("move_gripper_to", (o,)) for o in objects if o.endswith("cube")]


def main():
    steps = plan(get_obj_names())
    for i, step in enumerate(steps):
        print("{}: {}({})".format(i, step.name, ", ".join(step.args)))
    print(f"{sqrt(2):.3f} {math.pi:.2f}", sorted({"b": 1, "a": 2}.items()))
    total = sum(x * x for x in range(10))
    assert total == 285


if __name__ == "__main__":
    main()
