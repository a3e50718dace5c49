# rs274 -i only
from stdglue import *
