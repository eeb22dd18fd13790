#include <cstdio>
int main() { std::puts("fastcal: under construction"); return 0; }
