# expect: rejected
exec("import os; os.system('touch @MARKER@/exec')")
eval("__import__('os')")
