# Included after the find_package calls of an interface package built against a
# venv of the registry's wheels (interfaces/simulation_interfaces,
# test/interfaces/tf2_msgs).
#
# The registry wheels were built elsewhere: some imported targets name that
# builder's Python and numpy include folders, which do not exist here. Drop
# the include folders that do not exist (this build finds its own Python).
get_property(imported DIRECTORY PROPERTY IMPORTED_TARGETS)
foreach(target IN LISTS imported)
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  if(dirs)
    set(kept "")
    foreach(dir IN LISTS dirs)
      if(EXISTS "${dir}" OR dir MATCHES "^\\$<")
        list(APPEND kept "${dir}")
      endif()
    endforeach()
    set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${kept}")
  endif()
endforeach()
