# expect: rejected
print(open("/etc/passwd").read())
