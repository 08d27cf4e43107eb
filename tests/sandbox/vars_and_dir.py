# expect: rejected
print(vars(robot))
print(dir(robot))
