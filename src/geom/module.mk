# sources of src/geom (C++17 and Eigen behind include/ncpar/geom.h)
LIB_CXXSRCS += $(wildcard src/geom/*.cpp)
