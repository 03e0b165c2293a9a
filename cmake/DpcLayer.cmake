# dpc_layer(<folder> [PUBLIC <targets>...] [PRIVATE <targets>...]): the folder's *.cpp as the
# static library dpc_<folder>. The internal libraries a layer may link are the ones the layer
# table in docs/design.md allows; scripts/check-layers.py checks every #include against it.
function(dpc_layer folder)
  cmake_parse_arguments(arg "" "" "PUBLIC;PRIVATE" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${folder}/*.cpp)
  add_library(dpc_${folder} STATIC ${sources})
  target_include_directories(dpc_${folder} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(dpc_${folder} PUBLIC ${arg_PUBLIC} PRIVATE ${arg_PRIVATE})
endfunction()
