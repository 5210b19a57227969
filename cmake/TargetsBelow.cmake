# tofguard_targets_below(DIR OUT): every target defined in DIR and the
# directories below it (cmake/ProductPch.cmake, cmake/LinkGraph.cmake).
function(tofguard_targets_below dir out)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(sub ${subdirs})
    tofguard_targets_below(${sub} below)
    list(APPEND targets ${below})
  endforeach()
  set(${out} ${targets} PARENT_SCOPE)
endfunction()
