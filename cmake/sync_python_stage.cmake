# Removes from the staged package (build/python/animat) every Python module that python/animat no
# longer has, so that the stage holds exactly the library that `pip install .` would install (copying
# alone would keep a module that was moved out, e.g. into studies/).
#   cmake -DSOURCE=<repo>/python/animat -DSTAGE=<build>/python/animat -P sync_python_stage.cmake
if(NOT DEFINED SOURCE OR NOT DEFINED STAGE)
  message(FATAL_ERROR "sync_python_stage.cmake: pass -DSOURCE=<package dir> -DSTAGE=<staged package dir>")
endif()
file(GLOB staged_modules RELATIVE ${STAGE} ${STAGE}/*.py)
foreach(module IN LISTS staged_modules)
  if(NOT EXISTS ${SOURCE}/${module})
    file(REMOVE ${STAGE}/${module})
    message(STATUS "animat_python_stage: removed ${module} (no longer in python/animat)")
  endif()
endforeach()
