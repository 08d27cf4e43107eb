# expect: rejected
print("{0.__class__.__base__.__subclasses__}".format(()))
