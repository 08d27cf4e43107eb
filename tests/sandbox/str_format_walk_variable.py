# expect: rejected
template = "{0.gi_frame.f_globals}"
def gen():
    yield 1
print(template.format(gen()))
