# Run with cmake -P before `cargo rustc` links the cdylib with its SONAME. A plain
# `cargo build` in the same target directory links it again without one, and cargo's
# fingerprint does not cover the link argument, so `cargo rustc` would take that library as
# fresh. Removing a library that lacks the SONAME makes cargo link it again.
#   cmake -DSONAME=libvoussoir.so.<ABI> -DDIR=<target>/<profile> -P stale_soname.cmake
find_program(READELF readelf)
if(NOT READELF)
  message(WARNING "readelf not found (Debian: binutils): a library that a plain cargo build "
                  "left without the SONAME ${SONAME} is not relinked")
  return()
endif()
foreach(lib "${DIR}/libvoussoir.so" "${DIR}/deps/libvoussoir.so")
  if(EXISTS "${lib}")
    execute_process(COMMAND "${READELF}" -d "${lib}" OUTPUT_VARIABLE dynamic ERROR_QUIET)
    string(FIND "${dynamic}" "[${SONAME}]" at)
    if(at EQUAL -1)
      message(STATUS "${lib} lacks the SONAME ${SONAME}: cargo links it again")
      file(REMOVE "${lib}")
    endif()
  endif()
endforeach()
