# Finds the OpenCV modules we use as imported targets opencv::<module>.
# Debian ships OpenCVConfig.cmake only in the meta package libopencv-dev, which
# pulls in ~110 packages we do not need; the per-module -dev packages ship the
# headers and libraries, so we locate those directly when no config is found.
function(pinball_find_opencv)
  set(modules ${ARGN})
  find_package(OpenCV QUIET COMPONENTS ${modules})
  foreach(m IN LISTS modules)
    if(TARGET opencv::${m})
      continue()
    endif()
    add_library(opencv::${m} INTERFACE IMPORTED GLOBAL)
    if(OpenCV_FOUND)
      target_link_libraries(opencv::${m} INTERFACE opencv_${m})
      target_include_directories(opencv::${m} INTERFACE ${OpenCV_INCLUDE_DIRS})
      continue()
    endif()
    find_path(PINBALL_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
    find_library(PINBALL_OPENCV_${m}_LIBRARY opencv_${m} REQUIRED)
    target_include_directories(opencv::${m} INTERFACE ${PINBALL_OPENCV_INCLUDE_DIR})
    target_link_libraries(opencv::${m} INTERFACE ${PINBALL_OPENCV_${m}_LIBRARY})
  endforeach()
endfunction()
