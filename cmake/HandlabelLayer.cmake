# handlabel_layer(NAME) builds one layer folder as one static library named
# handlabel_<NAME>, from every .cc in the folder. The caller declares links with
# target_link_libraries(handlabel_<NAME> PUBLIC|PRIVATE ...).
function(handlabel_layer name)
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cc)
  list(FILTER sources EXCLUDE REGEX ".*_(main|fuzz)\\.cc$")
  add_library(handlabel_${name} STATIC ${sources})
  target_include_directories(handlabel_${name} PUBLIC ${PROJECT_SOURCE_DIR})
  set_target_properties(handlabel_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
