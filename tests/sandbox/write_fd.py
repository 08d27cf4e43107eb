# expect: rejected
import os
os.write(1, b'{"type":"result","nonce":"guess","result":{}}\n')
os.write(2, b"noise\n")
os.write(3, b'{"type":"result","nonce":"guess","result":{}}\n')
