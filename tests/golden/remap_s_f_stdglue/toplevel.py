# rs274 -i only: the remap module is stdglue.py (ncpar has it built in)
import remap
