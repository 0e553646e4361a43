# The lab path never links the simulator (design.md, "Layout"): a lab machine
# runs no physics engine, and a controller that could read the simulator's
# state would cheat (thesis 4.1). Nor does pinballd link what only the offline
# tools need. pinball_check_lab_links() walks every target a lab target links,
# directly or through others, and stops the configure step if it meets a
# forbidden one.

# Appends to <out> every target that <target> links, transitively.
function(_pinball_collect_links target out)
  set(found ${${out}})
  foreach(property LINK_LIBRARIES INTERFACE_LINK_LIBRARIES)
    get_target_property(libs ${target} ${property})
    if(NOT libs)
      continue()
    endif()
    foreach(lib IN LISTS libs)
      string(REGEX REPLACE "^\\$<LINK_ONLY:(.+)>$" "\\1" lib "${lib}")
      if(TARGET ${lib} AND NOT lib IN_LIST found)
        list(APPEND found ${lib})
        _pinball_collect_links(${lib} found)
      endif()
    endforeach()
  endforeach()
  set(${out} ${found} PARENT_SCOPE)
endfunction()

# pinball_check_lab_links(LAB <targets...> FORBIDDEN <targets...> [REASON <text>])
function(pinball_check_lab_links)
  cmake_parse_arguments(A "" "REASON" "LAB;FORBIDDEN" ${ARGN})
  if(NOT A_REASON)
    set(A_REASON "the lab path must not contain the simulator or its stand-ins (design.md, Layout)")
  endif()
  foreach(lab IN LISTS A_LAB)
    set(links "")
    _pinball_collect_links(${lab} links)
    foreach(forbidden IN LISTS A_FORBIDDEN)
      if(forbidden IN_LIST links)
        message(FATAL_ERROR "lab target ${lab} links ${forbidden}: ${A_REASON}")
      endif()
    endforeach()
  endforeach()
endfunction()
