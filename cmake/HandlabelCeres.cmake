# Ceres, found here once for every layer, test and benchmark that links it. Debian's
# Ceres (its own link line, and the BLAS::BLAS target that its SuiteSparse lookup makes
# with FindBLAS) names ATLAS's libf77blas and libatlas, which libtorch-dev pulls in.
# Linked into a program beside LibTorch, ATLAS's sgemm_ then comes first in the symbol
# lookup and shadows the libblas.so.3 alternative (OpenBLAS, scripts/install-deps) that
# LibTorch calls: a training step ran 1.75x slower (docs/training.md "BLAS"). libblas
# and liblapack, also in those lists, provide the same Fortran symbols, so the
# ATLAS-only entries are dropped.
find_package(Ceres REQUIRED)
foreach(_target Ceres::ceres BLAS::BLAS)
  if(TARGET ${_target})
    get_target_property(_libs ${_target} INTERFACE_LINK_LIBRARIES)
    list(FILTER _libs EXCLUDE REGEX "/lib(f77blas|atlas)\\.so$")
    set_target_properties(${_target} PROPERTIES INTERFACE_LINK_LIBRARIES "${_libs}")
  endif()
endforeach()
unset(_libs)
unset(_target)
