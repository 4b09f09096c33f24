# Checks that every #include "animat/NAME.hpp" points to the same layer or one below (CMakeLists.txt
# lists the layers, their sources and their headers). Run by ctest (Layers.IncludesPointDown):
#
#   cmake -DANIMAT_LAYERS_FILE=<build>/animat_layers.cmake -P cmake/check_layers.cmake
#
# The layers file sets ANIMAT_SOURCE_DIR, ANIMAT_LAYER_NAMES (bottom first) and, per layer L,
# ANIMAT_LAYER_<L>_SOURCES (paths relative to the source tree) and ANIMAT_LAYER_<L>_HEADERS (names).
cmake_minimum_required(VERSION 3.25)
include(${ANIMAT_LAYERS_FILE})

set(index 0)
foreach(layer ${ANIMAT_LAYER_NAMES})
  foreach(header ${ANIMAT_LAYER_${layer}_HEADERS})
    set(level_of_${header} ${index})
    set(layer_of_${header} ${layer})
  endforeach()
  math(EXPR index "${index} + 1")
endforeach()

# Every public header belongs to a layer.
file(GLOB public_headers RELATIVE ${ANIMAT_SOURCE_DIR}/include/animat ${ANIMAT_SOURCE_DIR}/include/animat/*.hpp)
set(problems "")
foreach(file ${public_headers})
  string(REGEX REPLACE "\\.hpp$" "" header ${file})
  if(NOT DEFINED level_of_${header})
    string(APPEND problems "  include/animat/${file}: in no layer (add it to a layer's headers in CMakeLists.txt)\n")
  endif()
endforeach()

# Every library source belongs to a layer (a new one is listed in CMakeLists.txt).
set(all_layer_sources "")
foreach(layer ${ANIMAT_LAYER_NAMES})
  list(APPEND all_layer_sources ${ANIMAT_LAYER_${layer}_SOURCES})
endforeach()
file(GLOB library_sources RELATIVE ${ANIMAT_SOURCE_DIR} ${ANIMAT_SOURCE_DIR}/src/*.cpp ${ANIMAT_SOURCE_DIR}/src/effects/*.cpp)
foreach(file ${library_sources})
  if(NOT file IN_LIST all_layer_sources)
    string(APPEND problems "  ${file}: in no layer (add it to a layer's sources in CMakeLists.txt)\n")
  endif()
endforeach()

set(checked 0)
set(index 0)
foreach(layer ${ANIMAT_LAYER_NAMES})
  set(files ${ANIMAT_LAYER_${layer}_SOURCES})
  foreach(header ${ANIMAT_LAYER_${layer}_HEADERS})
    list(APPEND files include/animat/${header}.hpp)
  endforeach()
  foreach(file ${files})
    file(STRINGS ${ANIMAT_SOURCE_DIR}/${file} lines REGEX "^[ \t]*#[ \t]*include[ \t]+\"animat/[A-Za-z0-9_]+\\.hpp\"")
    foreach(line ${lines})
      string(REGEX REPLACE ".*\"animat/([A-Za-z0-9_]+)\\.hpp\".*" "\\1" target "${line}")
      math(EXPR checked "${checked} + 1")
      if(NOT DEFINED level_of_${target})
        string(APPEND problems "  ${file} includes animat/${target}.hpp, which is in no layer\n")
      elseif(level_of_${target} GREATER index)
        string(APPEND problems "  ${file} (${layer}) includes animat/${target}.hpp (${layer_of_${target}}): upward\n")
      endif()
    endforeach()
  endforeach()
  math(EXPR index "${index} + 1")
endforeach()

if(problems)
  message(FATAL_ERROR "Layering (model < simulation < evaluation < evolution < run) broken:\n${problems}")
endif()
message(STATUS "layers: ${checked} includes checked, none upward")
