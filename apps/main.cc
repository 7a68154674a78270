#include "apps/commands.h"

int main(int argc, char** argv) { return handlabel::RunHandlabel(argc, argv); }
