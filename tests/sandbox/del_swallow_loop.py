# expect: rejected
class Immortal:
    def __del__(self):
        while True:
            try:
                pass
            except BaseException:
                pass

x = Immortal()
del x
